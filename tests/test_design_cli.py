"""``tunnelkit design``: JSON shape, the 28 GHz question, bad input naming the parameter."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tunnelkit import design
from tunnelkit.cli import main

KEYS = {
    "array",
    "n_elements",
    "aperture_diagonal_m",
    "status",
    "reason",
    "gaps",
    "srnf_valid_share",
    "srnf_valid_share_by_surface",
    "peb_median_m",
    "peb_p90_m",
    "predicted_median_m",
    "predicted_p90_m",
    "met_share",
    "error_median_m",
    "error_p90_m",
    "error_p90_route_m",
    "error_p90_ci95_m",
    "rmse_m",
    "rmse_ci95_m",
    "runs",
    "units",
    "drives_per_unit",
    "unit_yield",
    "unit_yield_ci95",
    "unit_p90_m",
    "unit_rmse_m",
    "pcrlb_rms_m",
    "hybrid_bound_rms_m",
    "rmse_over_pcrlb",
    "rmse_over_hybrid_bound",
    "unit_rmse_over_pcrlb_min",
    "predicted_drive_rms_m",
    "rmse_over_predicted_drive",
    "rmse_over_predicted",
    "per_epoch",
}
#: keys filled by the Monte-Carlo only
MC_KEYS = {
    k for k in KEYS if k.startswith(("error", "rmse", "unit_", "pcrlb", "hybrid", "tracker"))
}
MC_KEYS |= {"predicted_drive_rms_m"}
INPUTS = {"scenario", "arrays", "fc", "bandwidth", "target", "share", "criterion", "impairments"}


def test_json_answers_the_28ghz_question(capsys):
    argv = ["design", "example-rectangular-28ghz", "--ideal", "--arrays", "2x2", "3x3", "4x4"]
    argv += ["8x8"]
    assert main([*argv, "--target", "0.15", "--format", "json"]) == 0
    out = json.loads(capsys.readouterr().out)
    top = {"scenario", "inputs", "criterion", "arrays", "paired", "recommendation", "warnings"}
    assert set(out) == top and out["paired"] == {}  # no units: nothing to pair
    assert out["scenario"] == "example-rectangular-28ghz" and out["criterion"] == "achievable"
    assert INPUTS | {"seed", "units", "mode", "eps_phi", "spacing_wl"} <= set(out["inputs"])
    assert {"drives_per_unit", "required_yield", "max_units", "settle_s"} <= set(out["inputs"])
    assert out["inputs"]["impairments"]["phase_error_deg"] == 0.0
    assert out["inputs"]["impairments_preset"] == "ideal"
    assert [a["array"] for a in out["arrays"]] == ["2x2", "3x3", "4x4", "8x8"]
    for a in out["arrays"]:
        assert set(a) == KEYS
        assert a["runs"] == a["units"] == 0 and a["status"] == "bound only"
        assert all(a[k] is None for k in MC_KEYS), [k for k in MC_KEYS if a[k] is not None]
        ep = a["per_epoch"]
        assert len(ep["x_m"]) == len(ep["peb_m"]) == len(ep["predicted_m"]) == 40
        assert ep["error_median_m"] is None
        # no impairments: the prediction is the noise of the tracker's block-weighted fix,
        # never below the PEB
        assert all(a >= p for a, p in zip(ep["predicted_m"], ep["peb_m"], strict=True))
    by = {a["array"]: a for a in out["arrays"]}
    assert by["8x8"]["n_elements"] == 64
    # lambda/2 at 28 GHz: 7 spacings along each side, diagonal 7 sqrt(2) lambda/2
    assert by["8x8"]["aperture_diagonal_m"] == pytest.approx(7 * np.sqrt(2) * 299792458 / 28e9 / 2)
    # the ceiling 20 cm above the array: SR-NF fails for 8x8 everywhere, holds for 2x2; it is
    # information under the achievable criterion, not a gate
    assert by["8x8"]["srnf_valid_share"] == 0.0 and by["2x2"]["srnf_valid_share"] == 1.0
    assert by["8x8"]["srnf_valid_share_by_surface"]["ceiling"] == 0.0
    assert by["8x8"]["status"] == "bound only"
    assert by["2x2"]["peb_median_m"] > by["8x8"]["peb_median_m"]
    assert set(out["recommendation"]) == {"array", "reason", "basis", "route"}
    assert out["recommendation"]["route"] is None  # no Monte-Carlo: no route decided
    assert out["recommendation"]["basis"] == "none" and out["recommendation"]["array"] is None
    assert any("bounds and predictions only" in w for w in out["warnings"])


def test_wideband_model_drops_the_wideband_bias_and_is_an_input(capsys):
    argv = ["design", "example-rectangular-28ghz", "--ideal", "--arrays", "8x8"]
    argv += ["--format", "json"]
    out = {}
    for extra in ([], ["--wideband", "--no-wideband-model"], ["--wideband"]):
        assert main([*argv, *extra]) == 0
        out[" ".join(extra)] = json.loads(capsys.readouterr().out)
    out["--wideband --wideband-model"] = out.pop("--wideband")  # the model follows the channel
    imp = out["--wideband --wideband-model"]["inputs"]["impairments"]
    assert imp["spatial_wideband"] is True and imp["wideband_model"] is True
    out["--wideband"] = out.pop("--wideband --no-wideband-model")
    assert out["--wideband"]["inputs"]["impairments"]["wideband_model"] is False
    ach = {k: v["arrays"][0]["predicted_p90_m"] for k, v in out.items()}
    peb = out[""]["arrays"][0]["peb_p90_m"]
    assert ach["--wideband"] > 1.2 * peb  # the plain fit's wideband bias, as the tracker weighs
    # modelled, the term costs nothing: the ideal prediction (the tracker's block-weighted
    # fix, not below the PEB)
    assert ach["--wideband --wideband-model"] == ach[""] >= peb


def test_srnf_criterion_keeps_the_gate(capsys):
    argv = ["design", "example-rectangular-28ghz", "--ideal", "--arrays", "2x2", "3x3", "4x4"]
    argv += ["8x8", "--target", "0.15", "--criterion", "srnf", "--format", "json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    by = {a["array"]: a for a in out["arrays"]}
    # SR-NF breaks on the ceiling path from 4x4 on: the gate fails those epochs
    assert out["criterion"] == "srnf"
    assert by["3x3"]["met_share"] > by["4x4"]["met_share"] > by["8x8"]["met_share"] == 0.0
    assert by["4x4"]["srnf_valid_share_by_surface"]["ceiling"] < 0.9


def test_table_and_overrides(capsys):
    argv = ["design", "italiano2026-straight", "--arrays", "4x4", "10x10", "--fc", "28GHz"]
    assert main([*argv, "--bandwidth", "400MHz", "--tilt", "20", "--target", "0.05"]) == 0
    out = capsys.readouterr().out
    assert "fc 28 GHz, bandwidth 400 MHz" in out and "recommendation (none):" in out
    assert "unit yield" in out and "criterion: achievable" in out
    assert "10x10" in out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--arrays", "8y8"], "arrays: cannot read '8y8'"),
        (["--arrays", "64x64"], "arrays: the 64x64 array"),
        (["--mount-height", "9"], "mount_height: 9 m puts the base-station mount"),
        (["--share", "1.5"], "share"),
        (["--ideal", "--wideband-model"], "wideband_model: the estimator models the spatial-"),
    ],
)
def test_bad_input_names_the_parameter(capsys, extra, message):
    assert main(["design", "italiano2026-straight", *extra]) == 2
    assert message in capsys.readouterr().err


def test_an_array_that_does_not_fit_is_reported_beside_the_others(capsys):
    argv = ["design", "italiano2026-straight", "--arrays", "4x4", "64x64", "--format", "json"]
    assert main(argv) == 0
    out = json.loads(capsys.readouterr().out)
    bad = out["arrays"][1]
    assert bad["status"] == "error" and "elements outside" in bad["reason"]
    assert "mount '-x'" in bad["reason"] and bad["peb_median_m"] is None
    assert out["arrays"][0]["status"] == "bound only"
    assert any(w.startswith("64x64: arrays: the 64x64 array") for w in out["warnings"])


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--fc", "0GHz"], "fc: must be > 0"),
        (["--fc=-28GHz"], "fc: must be > 0"),
        (["--fc", "28 parsecs"], "fc: cannot read"),
        (["--bandwidth", "0"], "bandwidth: must be > 0"),
        (["--target", "0"], "target: must be > 0"),
        (["--target", "-1"], "target: must be > 0"),
        (["--target", "inf"], "target: must be > 0 and finite"),
        (["--start-sigma", "0"], "start_sigma: must be > 0"),
        (["--start-sigma", "nan"], "start_sigma: must be > 0"),
        (["--start-sigma", "one"], "start_sigma: expected a number"),
        (["--workers", "2", "--scheduler", "tcp://x:1"], "not allowed with"),
        (["--phase-error-deg", "-1"], "phase_error_deg: must be a finite number >= 0"),
        (["--phase-error-deg", "nan"], "phase_error_deg: must be"),
        (["--gain-error-db", "inf"], "gain_error_db: must be"),
        (["--dmc-share", "1"], "dmc_share: must be [0, 1)"),
        (["--dmc-share", "-0.1"], "dmc_share: must be [0, 1)"),
        (["--runs", "-1"], "units: must be >= 0"),
        (["--units", "two"], "units: expected an integer"),
        (["--drives-per-unit", "0"], "drives_per_unit: must be >= 1"),
        (["--yield", "1"], "yield: must be [0, 1)"),
        (["--yield", "0"], "yield: must be in (0, 1)"),
        (["--max-units", "0"], "max_units: must be >= 1"),
        (["--settle", "-1"], "settle: must be a finite number >= 0"),
        (["--trial-timeout", "0"], "trial_timeout: must be in (0, 86400] s"),
        (["--trial-timeout", "nan"], "trial_timeout: must be in (0, 86400] s"),
        (["--trial-timeout", "forever"], "trial_timeout: expected seconds"),
        (["--criterion", "eq51"], "invalid choice"),
        (["--mode", "fast"], "invalid choice"),
    ],
)
def test_argument_errors_exit_non_zero(capsys, extra, message):
    with pytest.raises(SystemExit) as exc:
        main(["design", "italiano2026-straight", *extra])
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_unknown_scenario_and_2d_tunnel(capsys):
    assert main(["design", "no-such-tunnel"]) == 2
    assert "unknown scenario" in capsys.readouterr().err
    with pytest.raises(ValueError, match=r"scenario: .* 2-D tunnel"):
        design.DesignSetup.from_scenario("jiang2023-straight")


def test_monte_carlo_is_seeded_and_reported():
    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    a = design.sweep_montecarlo(setup, "4x4", 2, 5, n_epochs=13)["4x4"]
    b = design.sweep_montecarlo(setup, "4x4", 2, 5, n_epochs=13)["4x4"]
    assert np.array_equal(a.errors, b.errors) and np.all(np.isfinite(a.errors))
    assert a.settled.tolist() == [10, 11, 12]  # the epochs 1 s after the start
    assert a.rmse_runs == pytest.approx(np.sqrt(np.mean(a.errors[:, a.settled] ** 2, axis=1)))
    # sigmas from this design, not 5.9 GHz constants: at least the CRLB, finite, positive
    pb = design.path_bounds(setup, "4x4")
    ok = np.all([np.isfinite(pb[k]) for k in ("d", "direction", "kappa")], axis=0)  # resolved
    assert a.sigmas["direction_rad"] >= np.median(pb["direction"][ok]) * (1 - 1e-6)
    assert a.sigmas["delta_d_m"] >= np.sqrt(2) * np.median(pb["d"][ok]) * (1 - 1e-6)


def test_a_scheduler_that_does_not_answer_fails_fast(capsys):
    import time

    t0 = time.perf_counter()
    argv = ["design", "italiano2026-straight", "--arrays", "4x4", "--units", "2"]
    rc = main([*argv, "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "2"])
    assert rc != 0 and time.perf_counter() - t0 < 120
    assert "scheduler" in capsys.readouterr().err


def test_monte_carlo_identical_on_two_workers():
    setup = design.DesignSetup.from_scenario("italiano2026-straight")
    serial = design.sweep_montecarlo(setup, "4x4", 2, 7, n_epochs=3)["4x4"]
    dask = design.sweep_montecarlo(setup, "4x4", 2, 7, n_epochs=3, workers=2)["4x4"]
    assert np.array_equal(serial.errors, dask.errors)


def test_json_reports_the_bounds_and_predictions_over_the_drive(capsys):
    argv = ["design", "example-rectangular-28ghz", "--arrays", "8x8", "--units", "2"]
    argv += ["--max-units", "2", "--phase-error-deg", "1", "--settle", "0.5"]
    assert main([*argv, "--n-epochs", "12", "--format", "json", "--no-progress"]) == 0
    a = json.loads(capsys.readouterr().out)["arrays"][0]
    assert a["units"] == 2 and a["runs"] == 4
    known = a["predicted_drive_rms_m"]
    assert known > 0
    assert a["rmse_over_predicted_drive"] == pytest.approx(a["rmse_m"] / known)
    # the bounds: every unit's below the one pooled over units (the calibration unknown)
    assert 0 < a["pcrlb_rms_m"] < a["hybrid_bound_rms_m"]
    assert a["rmse_over_hybrid_bound"] == pytest.approx(a["rmse_m"] / a["hybrid_bound_rms_m"])
    assert a["rmse_over_hybrid_bound"] > 1 and a["unit_rmse_over_pcrlb_min"] > 1


def test_start_sigma_reaches_the_json_and_the_table(capsys):
    argv = ["design", "example-rectangular-28ghz", "--arrays", "4x4", "--units", "2",
            "--max-units", "2", "--n-epochs", "6", "--settle", "0.2", "--no-progress"]  # fmt: skip
    assert main([*argv, "--start-sigma", "0.05", "--format", "json"]) == 0
    fine = json.loads(capsys.readouterr().out)
    assert fine["inputs"]["start_sigma_m"] == 0.05
    assert main([*argv, "--no-dead-reckoning", "--format", "json"]) == 0
    wide = json.loads(capsys.readouterr().out)
    assert "start_sigma_m" not in wide["inputs"] and "dead_reckoning" not in wide["inputs"]
    assert "dead_reckoning_p90_m" not in wide["arrays"][0]
    b = [r["arrays"][0]["pcrlb_rms_m"] for r in (fine, wide)]
    assert b[0] < b[1]  # the bounds' prior follows the entry fix
    assert main([*argv, "--start-sigma", "0.05"]) == 0
    assert "entry fix 0.05 m per axis" in capsys.readouterr().out
    assert main([*argv, "--format", "json"]) == 0  # dead reckoning on by default
    dr = json.loads(capsys.readouterr().out)
    assert dr["inputs"]["dead_reckoning"] is True and dr["arrays"][0]["dead_reckoning_p90_m"] > 0
    assert dr["arrays"][0]["pcrlb_rms_m"] == wide["arrays"][0]["pcrlb_rms_m"]
    # without the Monte-Carlo (no --units) there is no drive to reckon: nothing recorded
    assert main([*argv[:4], "--format", "json"]) == 0
    assert "dead_reckoning" not in json.loads(capsys.readouterr().out)["inputs"]


def test_the_trial_timeout_reaches_every_batch_and_a_stalled_sweep_exits_cleanly(
    capsys, monkeypatch
):
    """``--trial-timeout`` (seconds, or none) is what each batch of drives is run with
    (run_trials' ``trial_timeout``; default :data:`TRIAL_TIMEOUT_S`); a sweep it stops exits 1
    with the runner's message and the option named, not a traceback."""
    from tunnelkit.design import unitsweep
    from tunnelkit.runner import TRIAL_TIMEOUT_S, TrialTimeout

    told = []

    def recording(setup, specs, runs, seed, **kw):
        told.append(kw["trial_timeout"])
        raise TrialTimeout("trials [0, 1] of 2 (JAVELIN bound 4x4): none finished within 5 s")

    monkeypatch.setattr(unitsweep, "_sweep_montecarlo", recording)
    argv = ["design", "italiano2026-straight", "--arrays", "4x4", "--units", "1", "--no-progress"]
    for extra, want in (([], TRIAL_TIMEOUT_S), (["--trial-timeout", "7200"], 7200.0),
                        (["--trial-timeout", "None"], None)):  # fmt: skip
        assert main([*argv, *extra]) == 1
        err = capsys.readouterr().err
        assert told[-1] == want
        assert err.startswith("tunnelkit design: error: trials [0, 1] of 2")
        assert "--trial-timeout" in err and "Traceback" not in err
    with pytest.raises(ValueError, match="trial_timeout: must be > 0"):
        design.design_sweep(design.DesignSetup.from_scenario("italiano2026-straight"), "4x4",
                            trial_timeout=0.0)  # fmt: skip


def test_any_command_stopped_by_its_time_limit_exits_1_without_a_traceback(capsys, monkeypatch):
    """The command line turns a run's TrialTimeout (a TimeoutError) into an error line, status 1,
    for every command (here ``reproduce``, whose targets run with the runner's default limit)."""
    import tunnelkit.reproduce as reproduce
    from tunnelkit.runner import TrialTimeout

    def stalled(*args, **kw):
        raise TrialTimeout("trial 0 of 1 (jiang): ran longer than trial_timeout = 1800 s")

    monkeypatch.setattr(reproduce, "run", stalled)
    assert main(["reproduce", "jiang-table2", "--runs", "1", "--format", "json"]) == 1
    err = capsys.readouterr().err
    assert (
        err
        == "tunnelkit reproduce: error: trial 0 of 1 (jiang): ran longer than trial_timeout = 1800 s\n"
    )
