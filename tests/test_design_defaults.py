"""The design's default impairments (a calibrated array, a tunnel's measured diffuse power),
``--ideal``, and one meaning of the mount position (the scenario's reference antenna)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tunnelkit import design, propagation, scenarios
from tunnelkit.cli import main
from tunnelkit.design import impairments as di

SCENARIO = "example-rectangular-28ghz"


@pytest.fixture(scope="module")
def setup():
    return design.DesignSetup.from_scenario(SCENARIO)


def _json(capsys, *argv) -> dict:
    assert main(["design", SCENARIO, "--format", "json", *argv]) == 0
    return json.loads(capsys.readouterr().out)


def test_calibrated_preset_states_its_sources(setup):
    specs = [design.parse_array(a) for a in ("4x4", "8x8")]
    imp = design.preset_impairments("calibrated", setup, specs)
    assert imp.phase_error_deg == di.CALIBRATED_PHASE_ERROR_DEG == 1.5
    assert imp.gain_error_db == di.CALIBRATED_GAIN_ERROR_DB == 0.25
    assert imp.dmc_share == di.MEASURED_DIFFUSE_SHARE == 0.056
    refs = (Path(__file__).parents[1] / "REFERENCES.md").read_text()
    assert "Code-Modulated Embedded Test" in refs and "diffuse multipath analysis" in refs
    assert design.preset_impairments("ideal", setup, specs).ideal
    with pytest.raises(ValueError, match="name: expected one of calibrated, ideal"):
        design.preset_impairments("realistic", setup, specs)


@pytest.mark.parametrize(("arrays", "on"), [(("4x4", "8x8"), False), (("4x4", "16x16"), True)])
def test_wideband_term_where_the_band_calls_for_it(setup, arrays, on):
    """400 MHz at 28 GHz: a 16x16 spans 0.15 cycle of the band (on), an 8x8 0.07 (off); the
    estimator models the term whenever the channel has it."""
    specs = [design.parse_array(a) for a in arrays]
    cycles = design.impairments.wideband_cycles(setup, specs)
    big = max(specs, key=lambda s: s.aperture(setup.fc))
    assert cycles == pytest.approx(big.aperture(setup.fc) * setup.config.bandwidth / 299_792_458.0)
    imp = design.preset_impairments("calibrated", setup, specs)
    assert imp.spatial_wideband is on and imp.wideband_model is on
    assert (cycles > di.WIDEBAND_CYCLES) is on


def test_default_is_calibrated_and_ideal_is_asked_for(capsys):
    """Without options the answer carries the calibrated set and names it; --ideal gives the
    ideal case, with the warning that it is the optimistic one; one option changes one field."""
    out = _json(capsys, "--arrays", "4x4", "8x8", "--n-epochs", "30")
    imp = out["inputs"]["impairments"]
    assert out["inputs"]["impairments_preset"] == "calibrated"
    assert (imp["phase_error_deg"], imp["gain_error_db"], imp["dmc_share"]) == (1.5, 0.25, 0.056)
    assert not any("the optimistic case" in w for w in out["warnings"])
    ideal = _json(capsys, "--arrays", "4x4", "8x8", "--n-epochs", "30", "--ideal")
    assert ideal["inputs"]["impairments_preset"] == "ideal"
    assert not any(ideal["inputs"]["impairments"][k] for k in ("phase_error_deg", "dmc_share"))
    assert any("the optimistic case" in w for w in ideal["warnings"])
    # the calibrated array's prediction is above the ideal's at every array
    for a, b in zip(out["arrays"], ideal["arrays"], strict=True):
        assert a["predicted_p90_m"] > b["predicted_p90_m"]
    one = _json(capsys, "--arrays", "4x4", "--n-epochs", "30", "--phase-error-deg", "2")
    assert one["inputs"]["impairments"]["phase_error_deg"] == 2.0
    assert one["inputs"]["impairments"]["gain_error_db"] == 0.25
    assert one["inputs"]["impairments_preset"] == "calibrated, changed: phase_error_deg"
    both = _json(capsys, "--arrays", "4x4", "--n-epochs", "30", "--ideal", "--dmc-share", "0.01")
    assert both["inputs"]["impairments"]["dmc_share"] == 0.01
    assert both["inputs"]["impairments"]["phase_error_deg"] == 0.0


def test_no_wideband_turns_the_estimator_model_off_too(capsys):
    out = _json(capsys, "--arrays", "16x16", "--n-epochs", "20", "--no-wideband")
    imp = out["inputs"]["impairments"]
    assert not imp["spatial_wideband"] and not imp["wideband_model"]
    assert any("the band calls for it" in w for w in out["warnings"])


def test_python_default_equals_the_command_line_default(setup):
    rep = design.design_sweep(setup, ["4x4"], n_epochs=20)
    assert rep.settings["impairments_preset"] == "calibrated"
    assert rep.settings["impairments"]["phase_error_deg"] == 1.5
    with pytest.raises(TypeError, match="impairments: expected 'calibrated', 'ideal'"):
        design.design_sweep(setup, ["4x4"], n_epochs=20, impairments=1.5)
    with pytest.raises(ValueError, match="impairments: expected one of"):
        design.design_sweep(setup, ["4x4"], n_epochs=20, impairments="optimistic")


@pytest.mark.parametrize("name", [SCENARIO, "italiano2026-straight", "italiano2026-slalom"])
def test_the_scenario_array_sits_where_the_file_puts_it(name):
    """One meaning of the mount position: the file's position + offset is the reference antenna;
    the design centres candidates on the centre of the file's array, so the file's own array,
    placed by the design, has every element where the scenario (and the channel) puts it."""
    sc = scenarios.load_scenario(name)
    setup = design.DesignSetup.from_scenario(sc)
    for arr in propagation.scenario_arrays(sc):
        mount = next(m for m in setup.mounts if m.name == arr.name)
        assert np.allclose(mount.centre, arr.world.mean(axis=0), atol=1e-12)
    n = round(float(np.sqrt(propagation.scenario_arrays(sc)[0].M)))  # the presets' square URAs
    placed = setup.arrays(f"{n}x{n}")
    for got, want in zip(placed, propagation.scenario_arrays(sc), strict=True):
        assert np.allclose(got.world, want.world, atol=1e-9)
        assert np.allclose(got.origin, want.origin, atol=1e-9)


def test_the_help_leads_with_at_most_15_options(capsys):
    """The main group holds the question (arrays, band, target, calibration, units, output);
    everything else sits in groups titled "advanced: ..."."""
    with pytest.raises(SystemExit):
        main(["design", "--help"])
    text = capsys.readouterr().out
    head = text[text.index("\noptions:\n") : text.index("\nadvanced: ")]
    opts = [ln.split()[0].rstrip(",") for ln in head.splitlines() if ln.startswith("  --")]
    assert "--ideal" in opts and "--units" in opts and "--plot" in opts
    assert len(opts) <= 15, opts
    assert text.count("\nadvanced: ") >= 4
    for hidden in ("--mount-height", "--wideband", "--max-units", "--channel", "--workers"):
        assert hidden in text[text.index("\nadvanced: ") :]


def test_unusual_impairments_warn_and_usual_ones_do_not(setup):
    """A diffuse share beyond three standard deviations of the tunnel campaign, or phase and
    gain errors no calibrated array keeps, warn; the calibrated set and its neighbours do not."""
    specs = [design.parse_array("8x8")]
    assert di.implausible_impairments(design.preset_impairments("calibrated", setup, specs)) == []
    assert di.implausible_impairments(design.DesignImpairments(dmc_share=0.2)) == []
    (w,) = di.implausible_impairments(design.DesignImpairments(dmc_share=0.999999999))
    assert "more than three standard deviations" in w and "1e-07 % of the power" in w
    (w,) = di.implausible_impairments(design.DesignImpairments(phase_error_deg=20))
    assert "20 deg per element" in w and "uncalibrated" in w
    (w,) = di.implausible_impairments(design.DesignImpairments(gain_error_db=3))
    assert "3 dB per element" in w
    assert (
        di.implausible_impairments(design.DesignImpairments(phase_error_deg=5, gain_error_db=1))
        == []
    )
