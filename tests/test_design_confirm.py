"""The recommendation confirmed on the channel route (design.confirm)."""

import json

import numpy as np
import pytest

from tunnelkit import design
from tunnelkit.cli import main
from tunnelkit.design.confirm import confirmation_candidates, next_candidate
from tunnelkit.signal_route.judging import calibration_share


def _report(statuses, rec):
    rows = [
        design.DesignRow(a, n, 0.01 * n, status=s)
        for (a, n), s in zip((("4x4", 16), ("8x8", 64), ("16x16", 256)), statuses, strict=True)
    ]
    return design.DesignReport(
        "x",
        rows,
        {"array": rec},
        {
            "mode": "bound",
            "units": 20,
            "drives_per_unit": 2,
            "settle_s": 1.0,
            "required_yield": 0.95,
        },
    )


def test_candidates_are_the_recommendation_and_the_smaller_undecided():
    assert confirmation_candidates(_report(["undecided", "met", "met"], "8x8")) == ["4x4", "8x8"]
    assert confirmation_candidates(_report(["not met", "met", "met"], "8x8")) == ["8x8"]
    assert confirmation_candidates(_report(["met", "met", "met"], "4x4")) == ["4x4"]
    # nothing met: the smallest candidate still open
    assert confirmation_candidates(_report(["not met", "undecided", "met"], None)) == ["8x8"]
    assert confirmation_candidates(_report(["not met", "error", "not met"], None)) == []
    with pytest.raises(TypeError, match="report"):
        confirmation_candidates("x")


def test_next_candidate_is_the_next_larger_not_ruled_out():
    rep = _report(["undecided", "not met", "met"], "4x4")
    assert next_candidate(rep, ["4x4"]) == "16x16"  # 8x8 ruled out by the bound route
    assert next_candidate(rep, ["16x16"]) is None
    assert next_candidate(_report(["met", "met", "met"], "4x4"), []) == "4x4"
    with pytest.raises(ValueError, match="confirmed"):
        next_candidate(rep, ["2x2"])
    with pytest.raises(TypeError, match="report"):
        next_candidate("x", [])


@pytest.mark.parametrize(
    ("channel", "runs_of", "array"),
    [
        # the recommended 4x4 straddles the target on the channel route: 8x8 is run next, met
        ({"4x4": "undecided", "8x8": "met", "16x16": "met"}, [["4x4"], ["8x8"]], "8x8"),
        # met at once: nothing else is run
        ({"4x4": "met", "8x8": "met", "16x16": "met"}, [["4x4"]], "4x4"),
        # nothing meets: every candidate run once, in order, and no recommendation
        ({"4x4": "not met", "8x8": "undecided", "16x16": "not met"},
         [["4x4"], ["8x8"], ["16x16"]], None),
    ],
)  # fmt: skip
def test_confirmation_escalates_while_none_is_met(monkeypatch, channel, runs_of, array):
    """The escalation's order and stopping rule, the channel route's verdicts given."""
    from tunnelkit.design import confirm, montecarlo

    calls = []

    def fake_sweep(setup, specs, runs, seed, **kw):
        calls.append([x.label for x in specs])
        return {x.label: x.label for x in specs}

    def fake_score(row, res, *args, **kw):
        row.status, row.reason = channel[res], f"channel {channel[res]}"

    monkeypatch.setattr(montecarlo, "sweep_montecarlo", fake_sweep)
    monkeypatch.setattr(confirm, "score_row", fake_score)
    rep = _report(["met", "met", "met"], "4x4")
    rep.settings.update(
        arrays=["4x4", "8x8", "16x16"], spacing_wl=0.5, impairments={}, seed=0, n_epochs=None,
        criterion="achievable", target=0.1, share=0.9,
    )  # fmt: skip
    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    conf = design.confirm_on_channel(rep, setup)
    assert calls == runs_of
    assert conf.recommendation["array"] == array
    assert [r.array for r in conf.confirmation] == [c[0] for c in runs_of]


def test_confirmation_keeps_the_sweeps_entry_fix(monkeypatch):
    from tunnelkit.design import confirm, montecarlo

    seen = []

    def fake_sweep(setup, specs, runs, seed, **kw):
        seen.append(kw.get("start_sigma"))
        return {x.label: x.label for x in specs}

    def fake_score(row, res, *args, **kw):
        row.status, row.reason = "met", "channel met"

    monkeypatch.setattr(montecarlo, "sweep_montecarlo", fake_sweep)
    monkeypatch.setattr(confirm, "score_row", fake_score)
    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    for extra, want in (({"start_sigma_m": 0.2}, 0.2), ({}, None)):
        rep = _report(["met", "met", "met"], "4x4")
        rep.settings.update(
            arrays=["4x4", "8x8", "16x16"], spacing_wl=0.5, impairments={}, seed=0, n_epochs=None,
            criterion="achievable", target=0.1, share=0.9, **extra,
        )  # fmt: skip
        design.confirm_on_channel(rep, setup)
        assert seen[-1] == want


def test_confirmation_reruns_on_the_channel_route_and_decides():
    """A short ideal drive, 2 runs: the recommended array is re-run on the channel route with
    the sweep's seed (its errors differ from the bound route's), the recommendation says which
    route decided, and the bound route's answer stays beside it."""
    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    kw = {"target": 1.0, "units": 2, "max_units": 2, "drives_per_unit": 1, "settle": 0.0}
    rep = design.design_sweep(setup, ["4x4"], n_epochs=4, seed=3, impairments="ideal", **kw)
    assert rep.recommendation["basis"] == "unit-yield"
    conf = design.confirm_on_channel(rep, setup)
    assert isinstance(conf, design.ConfirmedReport)
    assert conf.recommendation["route"] == "channel"
    assert conf.bound_recommendation["route"] == "bound"
    (row,) = conf.confirmation
    assert row.array == "4x4" and row.runs == 2
    assert row.error_p90_m != rep.rows[0].error_p90_m  # measured again, not copied
    assert rep.rows[0].error_p90_m is not None  # the bound route's row unchanged
    direct = design.sweep_montecarlo(setup, ["4x4"], 2, 3, mode="channel", n_epochs=4)["4x4"]
    k = design.counted_epochs(direct.t, 0.0)
    assert row.error_p90_m == design.share_quantile(direct.errors[:, k], 0.9)
    out = conf.to_json()
    assert out["confirmation"]["route"] == "channel"
    assert out["confirmation"]["arrays"][0]["array"] == "4x4"
    assert out["inputs"]["confirm_route"] == "channel"
    assert "confirmed on the channel route" in conf.to_table()
    with pytest.raises(ValueError, match="report"):
        design.confirm_on_channel(design.design_sweep(setup, ["4x4"], n_epochs=4, settle=0), setup)
    assert np.isfinite(out["arrays"][0]["error_p90_m"])
    assert out["inputs"]["model_error_share"] == 0.0  # the ideal channel: the white-noise test


def test_confirmation_under_calibration_error_says_what_it_judges():
    """Under calibration error the channel route judges its fits against noise plus the
    closed-form calibration share: the confirmation states that share in its inputs."""
    setup = design.DesignSetup.from_scenario("example-rectangular-28ghz")
    kw = {"target": 1.0, "units": 2, "max_units": 2, "drives_per_unit": 1, "settle": 0.0}
    rep = design.design_sweep(
        setup, ["4x4"], impairments={"phase_error_deg": 0.5}, n_epochs=2, seed=3, **kw
    )
    conf = design.confirm_on_channel(rep, setup)
    share = conf.to_json()["inputs"]["model_error_share"]
    assert share == pytest.approx(calibration_share(0.5, 0.0)) and share > 0
    assert "model_error_share" not in rep.to_json()["inputs"]  # the bound route has no fit test


def test_cli_confirm_needs_bound_runs(capsys):
    argv = ["design", "example-rectangular-28ghz", "--arrays", "4x4", "--confirm"]
    assert main(argv) == 2
    assert "--confirm" in capsys.readouterr().err
    assert main([*argv, "--units", "2", "--mode", "channel"]) == 2
    # --confirm-units: only with --confirm, at least one unit
    assert main([*argv[:-1], "--units", "2", "--confirm-units", "2"]) == 2
    assert "--confirm-units" in capsys.readouterr().err
    assert main([*argv, "--units", "2", "--confirm-runs", "0"]) == 2
    assert "--confirm-units" in capsys.readouterr().err


def test_cli_json_says_which_route_decided(capsys):
    argv = ["design", "example-rectangular-28ghz", "--arrays", "4x4", "--n-epochs", "4"]
    argv += ["--settle", "0", "--max-units", "2", "--drives-per-unit", "1"]
    assert main([*argv, "--units", "2", "--format", "json", "--no-progress"]) == 0
    assert json.loads(capsys.readouterr().out)["recommendation"]["route"] == "bound"
    assert main([*argv, "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out)["recommendation"]["route"] is None
