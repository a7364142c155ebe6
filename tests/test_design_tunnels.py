"""Generated rectangular tunnels through the design's lowest public bounds: every epoch's bound
is finite or a per-epoch gap with a named cause, never NaN; one epoch's value does not depend on
the rest of the route; invalid inputs are refused up front with the parameter named.

Built on :class:`tunnelkit.design.DesignSetup`, :func:`~tunnelkit.design.route_bounds`,
:func:`~tunnelkit.design.path_error_model` and :func:`~tunnelkit.design.predicted_error` only
(not on the report). Each generated tunnel is one ceiling mount with one array looking along
the lane (azimuth 0 or 180), tilted down, the vehicle driving towards it from up to 1.5 km
away; the long routes are evaluated at a few epochs (the first, the last, one in between), which
is also what the locality check compares with the whole set. ``COUNTS`` records what was tried
and found; ``test_counts`` prints it (``pytest -s``) and asserts the search was not empty.
"""

from __future__ import annotations

import tomllib
from collections import Counter

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tunnelkit import design
from tunnelkit.design import DesignImpairments, path_error_model, predicted_error, route_bounds
from tunnelkit.scenarios import ScenarioError, scenario_from_dict, scenario_path

ARRAYS = ("4x4", "8x8", "16x16")
COUNTS: Counter = Counter()

with open(scenario_path("example-rectangular-28ghz"), "rb") as fh:
    BASE = tomllib.load(fh)


def _raw(p: dict) -> dict:
    """The example scenario as a rectangular tube around the generated lane and mount."""
    raw = {k: dict(v) if isinstance(v, dict) else v for k, v in BASE.items()}
    sign = 1.0 if p["azimuth"] == 0.0 else -1.0
    far = p["near"] + p["lane"]
    raw["name"] = "generated"
    raw["tunnel"] = {
        "kind": "rectangular",
        "length": 2.0 * (far + 20.0),
        "width": p["width"],
        "height": p["height"],
    }
    raw["base_station"] = {
        "position": [0.0, p["mount_y"], p["mount_z"]],
        "arrays": [
            {"name": "bs", "shape": [2, 2], "azimuth_deg": p["azimuth"], "tilt_deg": p["tilt"]}
        ],
    }
    raw["trajectory"] = {
        **BASE["trajectory"],
        "x_start": sign * far,
        "x_end": sign * p["near"],
        "y": p["lane_y"],
        "height": p["ue_height"],
    }
    return raw


@st.composite
def tunnels(draw):
    width = draw(st.floats(4.0, 30.0))
    height = draw(st.floats(3.5, 12.0))
    return {
        "width": width,
        "height": height,
        "mount_y": draw(st.floats(-0.5, 0.5)) * (width - 1.0),
        "mount_z": height - draw(st.floats(0.15, 0.5 * height - 0.5)),
        "tilt": draw(st.floats(0.0, 45.0)),
        "azimuth": draw(st.sampled_from([0.0, 180.0])),
        "lane_y": draw(st.floats(-0.5, 0.5)) * (width - 1.0),
        "ue_height": draw(st.floats(0.5, min(2.5, height - 1.0))),
        "near": draw(st.floats(2.0, 20.0)),
        "lane": draw(st.floats(20.0, 1500.0)),
    }


@st.composite
def impairment_sets(draw):
    return [
        DesignImpairments(),
        DesignImpairments(phase_error_deg=draw(st.floats(0.5, 2.0))),
        DesignImpairments(gain_error_db=draw(st.floats(0.05, 0.2))),
    ]


def _check_bound(b, geometry, tag: str) -> None:
    """Finite where valid; a gap (inf, never NaN) elsewhere, with a reason naming it."""
    for name in ("peb", "predicted", "calibration", "wideband", "diffuse", "noise"):
        assert not np.isnan(getattr(b, name)).any(), f"{tag}: NaN in {name}"
    assert np.array_equal(b.valid, np.isfinite(b.predicted)), tag
    ok = b.valid
    assert np.all(b.predicted[ok] >= b.peb[ok] * (1 - 1e-9)), tag
    if not ok.all():
        assert b.reason and "x = " in b.reason, f"{tag}: a gap without a cause: {b.reason!r}"
        COUNTS["gap epochs"] += int((~ok).sum())
    COUNTS["epochs finite"] += int(ok.sum())
    if b.reason:
        COUNTS["rows with a named gap or unresolved path"] += 1


@settings(
    max_examples=80,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(p=tunnels(), imps=impairment_sets(), pick=st.integers(0, 10**6))
def test_every_epoch_is_finite_or_a_named_gap(p, imps, pick):
    sc = scenario_from_dict(_raw(p), "generated.toml")
    setup = design.DesignSetup.from_scenario(sc)
    T = len(setup.trajectory)
    epochs = np.unique([0, pick % T, T - 1])
    COUNTS["tunnels"] += 1
    local_done = False
    for spec in ARRAYS:
        try:
            setup.arrays(spec)
        except ValueError as exc:  # refused up front, the parameter named
            assert str(exc).startswith("arrays: "), exc
            COUNTS["arrays refused (do not fit)"] += 1
            continue
        g = design.route_geometry(setup, spec, epochs=epochs)
        rb = route_bounds(setup, spec, geometry=g)
        assert not np.isnan(rb.peb).any() and np.all(rb.peb[g.exists.any(axis=1)] > 0)
        for imp in imps:
            COUNTS["tunnel x array x impairment"] += 1
            tag = f"{p} {spec} {imp}"
            m = path_error_model(setup, spec, imp, geometry=g)  # validates: finite where it exists
            for name in ("crlb", "cov", "bias", "k_phase", "k_gain"):
                v = getattr(m, name)
                assert v is None or not np.isnan(v).any(), f"{tag}: NaN in {name}"
            assert not np.any(m.exists & m.unresolved)
            assert np.array_equal(m.exists | m.unresolved, g.exists)
            COUNTS["paths left out (unresolved)"] += int(m.unresolved.sum())
            b = predicted_error(setup, spec, imp, geometry=g)
            assert np.array_equal(b.peb, rb.peb, equal_nan=True)
            _check_bound(b, g, tag)
            if not local_done and imp.phase_error_deg > 0:
                # one epoch alone gives the value it has among the others
                alone = predicted_error(setup, spec, imp, epochs=epochs[-1:])
                a, c = alone.predicted[0], b.predicted[-1]
                assert (np.isinf(a) and np.isinf(c)) or np.isclose(a, c, rtol=1e-7), tag
                local_done = True
                COUNTS["locality checks"] += 1


@pytest.mark.parametrize(
    ("change", "name"),
    [
        ({"tunnel": {"width": -8.0}}, "tunnel.width"),
        ({"tunnel": {"height": 0.0}}, "tunnel.height"),
        ({"trajectory": {"y": 9.0}}, "trajectory"),
        ({"base_station": {"position": [0.0, 0.0, 7.0]}}, "base_station"),
        ({"base_station": {"arrays": [{"shape": [2, 2], "tilt_deg": 120.0}]}}, "tilt_deg"),
    ],
)
def test_invalid_tunnels_are_refused_naming_the_parameter(change, name):
    p = {"width": 8.0, "height": 6.0, "mount_y": 0.0, "mount_z": 5.8, "tilt": 20.0}
    p |= {"azimuth": 0.0, "lane_y": -2.0, "ue_height": 1.5, "near": 5.0, "lane": 100.0}
    raw = _raw(p)
    for sec, vals in change.items():
        raw[sec] = {**raw[sec], **vals}
    with pytest.raises(ScenarioError, match=name.replace(".", r"\.")):
        scenario_from_dict(raw, "generated.toml")
    COUNTS["invalid inputs refused"] += 1


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda s: DesignImpairments(phase_error_deg=-0.5), "phase_error_deg"),
        (lambda s: DesignImpairments(gain_error_db=float("nan")), "gain_error_db"),
        (lambda s: s.variant(mount_height=6.5), "mount_height"),
        (lambda s: s.variant(tilt_deg=95.0), "tilt_deg"),
        (lambda s: s.arrays("128x128"), "arrays"),
        (lambda s: predicted_error(s, "4x4", epochs=[10**6]), "epochs"),
    ],
)
def test_invalid_design_inputs_are_refused_naming_the_parameter(call, name):
    p = {"width": 8.0, "height": 6.0, "mount_y": 0.0, "mount_z": 5.8, "tilt": 20.0}
    p |= {"azimuth": 0.0, "lane_y": -2.0, "ue_height": 1.5, "near": 5.0, "lane": 100.0}
    setup = design.DesignSetup.from_scenario(scenario_from_dict(_raw(p), "generated.toml"))
    with pytest.raises((ValueError, TypeError), match=rf"^{name}: "):
        call(setup)
    COUNTS["invalid inputs refused"] += 1


def test_counts():
    """What the search tried and found (``pytest -s`` prints it)."""
    print("\ndesign tunnels:", dict(COUNTS))
    if COUNTS["tunnels"]:  # the property test ran in this session
        assert COUNTS["tunnel x array x impairment"] >= 3 * COUNTS["tunnels"]
        assert COUNTS["epochs finite"] > 0
