"""The attribution study: the tracer's switches, the one-epoch fix, and a tiny traced case.

The traced case needs the ``rt`` extra (``make test`` installs it) and fails without it unless
``TUNNELKIT_SKIP_RT=1``: a 4 x 4 array, two epochs, 2,000 rays, no noisy draws.
"""

from __future__ import annotations

import dataclasses
import json
import os

import numpy as np
import pytest

from tunnelkit import propagation
from tunnelkit.rt.settings import RTSettings
from tunnelkit.scenarios import data_dir
from tunnelkit.signal_route import SignalRoute
from tunnelkit.studies.attribution import (
    CONFIGURATIONS,
    attribution,
    config_settings,
    one_epoch_fix,
    scenario_with_array,
)

SKIP_RT = os.environ.get("TUNNELKIT_SKIP_RT") == "1"
needs_sionna = pytest.mark.skipif(SKIP_RT, reason="TUNNELKIT_SKIP_RT=1")


def test_array_tracing_is_checked_and_leaves_the_default_key_alone():
    with pytest.raises(ValueError, match="array_tracing"):
        RTSettings(array_tracing="plane")
    with pytest.raises(ValueError, match="array_tracing"):
        RTSettings(array_tracing=1)
    # the default is left out of the record, so caches and stored records keep their key
    assert "array_tracing" not in RTSettings().record()
    stored = json.loads((data_dir() / "rt" / "traced_errors.json").read_text())
    assert RTSettings(**stored["rt_settings"]).record() == stored["rt_settings"]
    centre = RTSettings(array_tracing="centre")
    assert centre.record()["array_tracing"] == "centre"
    assert centre.fingerprint() != RTSettings().fingerprint()


def test_configurations_switch_what_they_say():
    base = RTSettings()
    assert config_settings(base, "scenario") == base
    assert config_settings(base, "no-diffuse").scattering_coefficient == 0.0
    assert config_settings(base, "depth-1").max_depth == 1
    off = config_settings(base, "all-off")
    assert (off.max_depth, off.scattering_coefficient, off.array_tracing) == (1, 0.0, "centre")
    assert off.wall_material == off.road_material == "metal"
    assert set(CONFIGURATIONS) >= {"first-order-centre", "diffuse-alone", "all-off"}
    with pytest.raises(ValueError, match="name"):
        config_settings(base, "no-such")


def test_scenario_with_array_mounts_the_shape():
    sc = scenario_with_array("italiano2026-straight", (3, 4))
    assert sc.name == "italiano2026-straight-3x4"
    assert all(a.M == 12 for a in propagation.scenario_arrays(sc))
    with pytest.raises(ValueError, match="shape"):
        scenario_with_array("italiano2026-straight", (1, 1))


def test_the_fix_of_the_true_paths_is_the_truth_and_a_bias_moves_it():
    route = SignalRoute.from_scenario(scenario_with_array("italiano2026-straight", (4, 4)))
    k = 10
    arr, paths = route.paths(k)
    ue = route.trajectory.position[k]
    u = np.stack([p.direction for p in paths])
    phi, psi = np.arctan2(u[:, 1], u[:, 0]), np.arcsin(u[:, 2])
    d = np.array([p.length for p in paths]) + 4.0  # a clock-bias range: estimated, no error
    assert np.hypot(*one_epoch_fix(phi, psi, d, paths, ue, arr.origin)) < 1e-6
    d_bad = d.copy()
    d_bad[0] += 1.0  # the LoS 1 m late
    assert np.hypot(*one_epoch_fix(phi, psi, d_bad, paths, ue, arr.origin)) > 0.05
    assert np.all(np.isnan(one_epoch_fix(phi[:1], psi[:1], d[:1], paths[:1], ue, arr.origin)))
    with pytest.raises(ValueError, match="sigmas"):
        one_epoch_fix(phi, psi, d, paths, ue, arr.origin, sigmas=(0.0, 1.0, 1.0))


@needs_sionna
def test_a_clean_traced_channel_is_eq1_and_diffuse_power_is_a_residual(tmp_path):
    res = attribution(
        arrays=[(4, 4)],
        configs=["first-order-centre", "diffuse-alone", "all-off"],
        epochs=[10, 20],
        draws=0,
        samples_per_src=2000,
        cache_dir=tmp_path,
    )
    summ = {s.config: s for s in res.summary}
    rows = {(r.config, r.kind): r for r in res.rows}
    assert summ["eq1"].residual_share < 1e-12
    assert rows["eq1", "all"].bias_d_m < 1e-6
    # all mechanisms off: at this small aperture the traced tensor is eq. 1 with the
    # spatial-wideband term (at 8 x 8 the centroid also sees the second ceiling facet's path,
    # which the image method does not list), and eq. 1's fit of it lands where its fit of the
    # image method's wideband tensor lands
    assert summ["all-off"].residual_share < 1e-3
    for kind in ("los", "ceiling", "road"):
        off, wb = rows["all-off", kind], rows["eq1+wideband", kind]
        assert abs(off.bias_d_m - wb.bias_d_m) < 0.05, kind
        assert off.bias_phi_deg < 0.5 and off.bias_d_m < 0.1, kind
    # diffuse scattering switched on (and nothing else): more residual, by orders of magnitude
    assert summ["diffuse-alone"].diffuse_share > 1e-3
    assert summ["diffuse-alone"].residual_share > 10 * summ["first-order-centre"].residual_share
    assert summ["first-order-centre"].diffuse_share == 0.0
    # one cache directory per configuration
    assert {p.name for p in (tmp_path / "attribution").iterdir()} == {
        "first-order-centre",
        "diffuse-alone",
        "all-off",
    }
    assert "| all-off | 4x4 | los |" in res.markdown()
    assert dataclasses.asdict(res.summary[0])["config"] == "eq1"
