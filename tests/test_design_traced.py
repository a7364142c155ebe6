"""The design's channel route on the ray-traced channel: the traced adapter, the per-array
errors cached with their provenance (refused when they do not match), the tracker told them,
and the sweep and report that say which error model they used.

Marked like the other ray-traced tests: they need the ``rt`` extra and fail without it unless
``TUNNELKIT_SKIP_RT=1``. A 4x4 array and two or three epochs, traced once into a temporary cache;
one setup object and one directory of error records for the module, so a record or a sweep's
drive another test has already measured is read back (its provenance checked) or reused, as in
one session of a user's.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import os
import re
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tunnelkit import design
from tunnelkit.design import traced, tracedbounds, tracedlos
from tunnelkit.odometry import AUTOMOTIVE
from tunnelkit.rt.cache import CACHE_ENV
from tunnelkit.simulation import drives, simulate_routes
from tunnelkit.simulation.prefilter import geometry_keep
from tunnelkit.tracking.javelin.noise import FixedNoise

SKIP_RT = os.environ.get("TUNNELKIT_SKIP_RT") == "1"
pytestmark = pytest.mark.skipif(SKIP_RT, reason="TUNNELKIT_SKIP_RT=1")

SCENARIO = "italiano2026-straight"
ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def traces(tmp_path_factory):
    """One ray-tracing cache for the module: a scene is traced once, as a user's cache keeps it."""
    return tmp_path_factory.mktemp("rt-cache")


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """One directory of error records for the module: a record (array, epochs) is measured by the
    first test that asks for it and read back, its provenance checked, by the others."""
    return tmp_path_factory.mktemp("records")


@pytest.fixture(scope="module")
def module_setup():
    """One setup object for the module: design_drive keeps a drive per setup object, so a sweep
    on a seed another test swept already reuses its drives, as a second sweep in a session does."""
    return design.DesignSetup.from_scenario(SCENARIO, channel="sionna")


@pytest.fixture
def setup(monkeypatch, traces, records, module_setup):
    """The paper tunnel on the ray-traced channel; traces in the module's cache, error records in
    the module's directory."""
    monkeypatch.setenv(CACHE_ENV, str(traces))
    monkeypatch.setattr(
        traced,
        "design_errors_path",
        lambda setup, spec, n_epochs=None: records / f"{parse(spec)}-{n_epochs}.json",
    )
    return module_setup


def parse(spec):
    return design.parse_array(spec).label


def test_the_traced_drive_is_the_drive_simulator_with_the_traced_adapters(setup):
    """Same seed: its "ml" drive is simulate_routes' (ML route, no condition); "ml-all" keeps
    every epoch's ML rows whatever the fit's verdict, "ml-traced" the rows geometry_keep keeps."""
    route = traced.traced_route(setup, "4x4")
    assert route.options.diffuse_floor and route.raytraced is not None
    got = traced.traced_drive(route, np.random.default_rng(3), n_epochs=2)
    ref = simulate_routes(
        route, np.random.default_rng(3), condition=None, extractions=("ml",), n_epochs=2
    )["ml"]
    assert list(got) == ["ml", "ml-all", "ml-traced"]
    np.testing.assert_array_equal(got["ml"].speed, ref.speed)
    assert got["ml"].faults == ref.faults
    for pa, pt in zip(got["ml-all"].epochs, got["ml-traced"].epochs, strict=True):
        assert pa is not None  # the fit's own test ignored
        assert pt is None or (set(pt.source) <= set(pa.source) and len(pt) <= len(pa))
    # the pre-filter is geometry_keep on the same epoch: redo epoch 0 and compare the rows kept
    from tunnelkit.simulation.reextract import ml_epoch

    with warnings.catch_warnings():  # every traced fit fails its own residual test
        warnings.simplefilter("ignore")
        ep0 = route.epoch(0, np.random.default_rng(3), tunnel=route.tunnel, refine="joint")
        ep = ml_epoch(ep0, route.config, route.ml_noise_power(0, ep0.snapshot, route.tunnel))
    kept = geometry_keep(ep, route)
    pt = got["ml-traced"].epochs[0]
    assert pt is not None and set(np.unique(pt.source)) == set(kept)


def _same_drive(a, b):
    for f in ("t", "truth", "speed", "heading", "base_station", "los", "n_true"):
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f))
    assert a.faults == b.faults and len(a.epochs) == len(b.epochs)
    for pa, pb in zip(a.epochs, b.epochs, strict=True):
        assert (pa is None) == (pb is None)
        if pa is not None:
            for f in ("source", "phi", "psi", "kappa", "d", "v", "cov"):
                np.testing.assert_array_equal(getattr(pa, f), getattr(pb, f))


def test_a_design_drive_is_kept_and_driven_again_only_when_something_differs(setup, monkeypatch):
    """design_drive: the sweep's traced drive, the "ml-traced" drive of traced_drive; asked for
    again with the same setup, array, epochs and generator state it is a copy of the kept
    drive and the generator ends where driving again leaves it; anything else drives again."""
    g_ref, g1 = np.random.default_rng(11), np.random.default_rng(11)
    ref = traced.traced_drive(traced.traced_route(setup, "4x4"), g_ref, n_epochs=1)["ml-traced"]
    first = traced.design_drive(setup, "4x4", g1, n_epochs=1)
    _same_drive(first, ref)
    assert g1.bit_generator.state == g_ref.bit_generator.state
    driven = []

    def count(route, rng, *, n_epochs=None):
        driven.append(n_epochs)
        rng.random()  # a drive draws from the generator
        return {"ml-traced": ref, "ml-all": ref}

    monkeypatch.setattr(traced, "traced_drive", count)
    g2 = np.random.default_rng(11)
    again = traced.design_drive(setup, "4x4", g2, n_epochs=1)
    assert driven == [] and again is not first
    _same_drive(again, ref)
    assert g2.bit_generator.state == g_ref.bit_generator.state
    assert g2.random() == g_ref.random()  # the entry fix drawn after it: the same draw
    # another seed, array, number of epochs or setup object (equal or not): driven again
    twin = design.DesignSetup.from_scenario(SCENARIO, channel="sionna")
    wide = design.ArraySpec(4, 4, spacing_wl=0.7)  # the same label, another array
    for st, spec, rng, n in ((setup, "4x4", 12, 1), (setup, "8x8", 11, 1), (setup, "4x4", 11, 2),
                             (twin, "4x4", 11, 1), (setup, wide, 11, 1)):  # fmt: skip
        traced.design_drive(st, spec, np.random.default_rng(rng), n_epochs=n)
    assert driven == [1, 1, 2, 1, 1]
    # the oldest drives are dropped beyond DRIVES_KEPT
    monkeypatch.setattr(traced, "DRIVES_KEPT", 2)
    monkeypatch.setattr(traced, "_DRIVES", type(traced._DRIVES)())
    for seed in (1, 2, 3, 1):
        traced.design_drive(setup, "4x4", np.random.default_rng(seed), n_epochs=1)
    assert len(traced._DRIVES) == 2 and driven[5:] == [1, 1, 1, 1]
    with pytest.raises(TypeError, match="rng"):
        traced.design_drive(setup, "4x4", 3)
    with pytest.raises(ValueError, match="setup"):
        traced.design_drive(design.DesignSetup.from_scenario(SCENARIO), "4x4", g1)


def _drive_tool():
    spec = importlib.util.spec_from_file_location(
        "traced_drive", ROOT / "tools" / "traced_drive.py"
    )
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    return tool


def test_the_stored_drive_is_what_driving_again_gives(setup, monkeypatch):
    """The shipped drive (tools/traced_drive.py; ``--check`` drives all of it again) is read for
    notebook 08's quick traced drive (its key is the current one). Driven again here from the
    same generator, its first epoch through the ML extraction and the others only drawn (their
    extraction draws nothing): the first epoch's measurements within 1 % of the sigmas the
    tracker reading them is told (bit for bit on the machine that wrote it; on another CPU or
    BLAS the trace's rounding differs, and the ML fit of two paths 10 cm apart amplifies it:
    measured 1e-4 rad and 0.3 mm, against told sigmas of degrees and decimetres), the V2X
    messages and the generator's end state bit for bit."""
    tool = _drive_tool()
    ((scenario, array, n_epochs, seed, stream),) = tool.CASES
    assert scenario == SCENARIO and seed == drives.HELD_OUT_SEED and n_epochs == 12
    path = traced.stored_drive_path(setup, array, n_epochs)
    stored = json.loads(path.read_text())
    assert stored["made_by"] == {"tool": "tools/traced_drive.py", "seed": seed, "stream": stream}
    rng = tool.case_rng(seed, stream)
    key = json.loads(json.dumps(traced.drive_key(setup, array, rng, n_epochs)))
    assert stored["key"] == key and key["n_epochs"] == 12 and key["rt_key"]["sionna_rt"]
    got = traced.stored_drive(setup, array, rng, n_epochs)
    assert got is not None and len(got.epochs) == 12
    # what the tracker reading the drive is told (the array's record of this route)
    rec = traced.design_errors(setup, array, n_epochs=n_epochs)
    cfg = traced.traced_javelin(setup, array, rec).config
    told = {**tracedbounds.config_sigmas(cfg), "v": cfg.sigma_speed}  # v: the nearest, a speed
    extracted, real = [], drives.ml_paths

    def first_only(*args, **kwargs):  # epoch 0 extracted, the others fail after their draws
        extracted.append(1)
        if len(extracted) > 1:
            raise ValueError("not extracted here")
        return real(*args, **kwargs)

    monkeypatch.setattr(drives, "ml_paths", first_only)
    g = tool.case_rng(seed, stream)
    both = traced.traced_drive(traced.traced_route(setup, array), g, n_epochs=n_epochs)
    fresh = both["ml-traced"]
    assert len(extracted) == 12 and g.bit_generator.state == rng.bit_generator.state
    for f in ("speed", "heading", "t", "truth", "velocity", "base_station"):
        np.testing.assert_array_equal(getattr(fresh, f), getattr(got, f), err_msg=f)
    for f in ("extraction", "clock_bias_limit", "reports_covariance", "scenario", "condition"):
        assert getattr(fresh, f) == getattr(got, f), f
    pa, pb = fresh.epochs[0], got.epochs[0]
    assert pa is not None and pb is not None
    np.testing.assert_array_equal(pa.source, pb.source)
    for f in ("phi", "psi", "kappa", "d", "v"):
        np.testing.assert_allclose(getattr(pa, f), getattr(pb, f), rtol=0, atol=0.01 * told[f],
                                   err_msg=f)  # fmt: skip
    assert pa.cov is None and pb.cov is None
    np.testing.assert_array_equal(fresh.truth_index[0], got.truth_index[0])
    np.testing.assert_allclose(fresh.sources[0], got.sources[0], rtol=1e-12, atol=0)
    assert (fresh.kinds[0], fresh.los[0], fresh.n_true[0]) == (got.kinds[0], got.los[0],
                                                              got.n_true[0])  # fmt: skip
    # every epoch's measurements (the line-of-sight tracker's input): the same epoch, every path
    every = traced.stored_drive(setup, array, tool.case_rng(seed, stream), n_epochs, kind="ml-all")
    pa, pb = both["ml-all"].epochs[0], every.epochs[0]
    assert len(pb.phi) >= len(got.epochs[0].phi)
    for f in ("phi", "psi", "kappa", "d"):
        np.testing.assert_allclose(getattr(pa, f), getattr(pb, f), rtol=0, atol=0.01 * told[f],
                                   err_msg=f)  # fmt: skip


def test_a_stored_drive_is_checked_refused_when_tampered_and_driven_when_foreign(
    setup, tmp_path, monkeypatch
):
    """A stored drive is read only for its own key and only when every field is what an encoded
    drive holds: a tampered file of the key is refused naming it; a file of another generator
    state is passed over, one of another scene or format with a warning; design_drive then
    drives."""
    tool = _drive_tool()
    ((_, array, n_epochs, seed, stream),) = tool.CASES
    stored = json.loads(traced.stored_drive_path(setup, array, n_epochs).read_text())
    p = tmp_path / "drive.json"

    def load(rec):
        p.write_text(json.dumps(rec) if isinstance(rec, dict) else rec)
        return traced.stored_drive(setup, array, tool.case_rng(seed, stream), n_epochs, path=p)

    assert load(stored) is not None
    # a kind missing, or the kinds ending in different generator states: refused
    one = {**stored, "drives": {"ml-traced": stored["drives"]["ml-traced"]}}
    with pytest.raises(ValueError, match=f"^path: {re.escape(str(p))} drives: expected one drive"):
        load(one)
    apart = json.loads(json.dumps(stored))
    apart["drives"]["ml-all"]["rng_end"]["state"]["state"] += 1
    with pytest.raises(ValueError, match="the kinds end in different generator states"):
        load(apart)

    def tampered(change):
        rec = json.loads(json.dumps(stored))
        change(rec["drives"]["ml-traced"])
        return rec

    ep = next(k for k, e in enumerate(stored["drives"]["ml-traced"]["epochs"]) if e["measurements"])

    def meas(rec):
        return rec["epochs"][ep]["measurements"]

    bad = {
        "a float written as an integer": lambda r: meas(r)["phi"].__setitem__(0, 1),
        "a NaN angle": lambda r: meas(r)["psi"].__setitem__(0, None),
        "an infinite speed": lambda r: r["speed"].__setitem__(3, float("inf")),
        "a speed missing": lambda r: r["speed"].pop(),
        "a path dropped from one field": lambda r: meas(r)["d"].pop(),
        "a negative curvature": lambda r: meas(r)["kappa"].__setitem__(0, -1.0),
        "a field missing": lambda r: r.pop("heading"),
        "a field added": lambda r: r["epochs"][ep].__setitem__("extra", 1),
        "an epoch dropped": lambda r: r["epochs"].pop(),
        "an unmeasured epoch without its fault": lambda r: r["epochs"][ep].update(
            measurements=None, truth_index=[]
        ),
        "a truth index beyond the true paths": lambda r: r["epochs"][ep]["truth_index"].__setitem__(
            0, 99
        ),
        "a boolean for a count": lambda r: r["n_true"].__setitem__(0, True),
        "another base station": lambda r: r["base_station"].__setitem__(2, 9.0),
        "another generator's end state": lambda r: r["rng_end"].update(bit_generator="MT19937"),
        "an end state out of range": lambda r: r["rng_end"]["state"].update(state=-1),
    }
    for what, change in bad.items():
        with pytest.raises(ValueError, match=f"^path: {re.escape(str(p))}"):
            load(tampered(change))
            pytest.fail(what)
    with pytest.raises(ValueError, match=f"path: {re.escape(str(p))} is not a stored drive"):
        load("{not json")
    # another generator state (another seed): passed over silently
    other = {**stored, "key": {**stored["key"], "rng_start": tool.case_rng(seed + 1, 0)
                               .bit_generator.state}}  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert load(other) is None
    # another scene or record format: passed over, saying what differs
    for field, value in (("rt_key", {**stored["key"]["rt_key"], "scene": "0" * 64}),
                         ("format", 1), ("n_epochs", 11)):  # fmt: skip
        with pytest.warns(
            RuntimeWarning, match=f"{re.escape(str(p))} holds this drive made with other {field}"
        ):
            assert load({**stored, "key": {**stored["key"], field: value}}) is None
    # a record of the previous format (one kind, "drive"): passed over with a warning, before
    # its fields are read
    old = {"key": {**stored["key"], "format": 1}, "drive": stored["drives"]["ml-traced"],
           "made_by": stored["made_by"]}  # fmt: skip
    with pytest.warns(RuntimeWarning, match="made with other format"):
        assert load(old) is None
    # a car's odometry (the scenario's [odometry]): the stored white messages are not its drive
    car = dataclasses.replace(
        setup, trajectory=dataclasses.replace(setup.trajectory, odometry=AUTOMOTIVE)
    )
    p.write_text(json.dumps(stored))
    with pytest.warns(RuntimeWarning, match="made with other odometry"):
        assert (
            traced.stored_drive(car, array, tool.case_rng(seed, stream), n_epochs, path=p) is None
        )
    # design_drive: the stored drive of its key read (no driving, the generator moved to the
    # drive's end), a foreign one driven
    driven = []

    def count(route, rng, *, n_epochs=None):
        driven.append(n_epochs)
        return {"ml-traced": "driven", "ml-all": "driven, every path"}

    monkeypatch.setattr(traced, "traced_drive", count)
    monkeypatch.setattr(traced, "stored_drive_path", lambda *a: p)
    monkeypatch.setattr(traced, "_DRIVES", type(traced._DRIVES)())
    p.write_text(json.dumps(stored))
    g = tool.case_rng(seed, stream)
    d = traced.design_drive(setup, array, g, n_epochs=n_epochs)
    assert driven == [] and len(d.epochs) == n_epochs
    assert g.bit_generator.state == stored["drives"]["ml-traced"]["rng_end"]
    g = tool.case_rng(seed, stream)  # the other kind: kept from the same read (no file read)
    monkeypatch.setattr(traced, "stored_drive_path", lambda *a: tmp_path / "none.json")
    every = traced.design_drive(setup, array, g, n_epochs=n_epochs, kind="ml-all")
    assert driven == [] and len(every.epochs) == n_epochs
    assert g.bit_generator.state == stored["drives"]["ml-all"]["rng_end"]
    monkeypatch.setattr(traced, "_DRIVES", type(traced._DRIVES)())  # read from the file
    monkeypatch.setattr(traced, "stored_drive_path", lambda *a: p)
    every = traced.design_drive(setup, array, tool.case_rng(seed, stream), n_epochs=n_epochs,
                                kind="ml-all")  # fmt: skip
    assert driven == [] and len(every.epochs) == n_epochs
    p.write_text(json.dumps(other))
    monkeypatch.setattr(traced, "_DRIVES", type(traced._DRIVES)())  # none kept in the process
    g = tool.case_rng(seed, stream)
    assert traced.design_drive(setup, array, g, n_epochs=n_epochs) == "driven"
    assert driven == [n_epochs]


def test_errors_are_measured_once_cached_and_refused_for_another_scene(setup, tmp_path):
    rec = traced.design_errors(setup, "4x4", n_epochs=2)
    p = rec["path"]
    assert rec["array"] == "4x4" and rec["scenario"] == SCENARIO and rec["n_epochs"] == 2
    assert rec["seed"] == traced.ERROR_SEED and rec["runs"] == traced.ERROR_RUNS
    assert rec["rt_key"]["sionna_rt"] and rec["rt_settings"]["max_depth"] >= 1
    # the record is what measure_design_errors gives on the same seed (the drives are seeded)
    again = traced.measure_design_errors(setup, "4x4", n_epochs=2)
    assert again["rows"] == rec["rows"]
    stored = json.loads(open(p).read())
    # read back, not re-measured
    assert traced.design_errors(setup, "4x4", n_epochs=2, measure=False)["rows"] == stored["rows"]
    # another scene key, array or epoch count: refused, naming what differs
    for field, value in (("rt_key", {**stored["rt_key"], "scene": "0" * 64}), ("array", "8x8"),
                         ("n_epochs", 5)):  # fmt: skip
        bad = tmp_path / "bad.json"
        bad.write_text(json.dumps({**stored, field: value}))
        with pytest.raises(ValueError, match=f"path: .*{field}"):
            traced.design_errors(setup, "4x4", n_epochs=2, path=bad)
    with pytest.raises(FileNotFoundError, match="path"):
        traced.design_errors(setup, "4x4", n_epochs=1, measure=False)


def test_the_tracker_is_told_the_measured_errors(setup):
    rec = traced.design_errors(setup, "4x4", n_epochs=2)
    d = traced.traced_javelin(setup, "4x4", rec)
    row = {r[0]: r for r in rec["rows"]}["all"]
    assert isinstance(d.noise, FixedNoise)

    def f(q):  # the long-run inflation of the record's lag-1 correlation (1 without one)
        r = rec.get("correlation", {}).get(q, {}).get("r", np.nan)
        r = 0.0 if not np.isfinite(r) else min(max(r, 0.0), 0.9)
        return np.sqrt((1 + r) / (1 - r))

    assert set(rec["correlation"]) == {"phi", "psi", "kappa", "delta_d"}
    assert d.config.sigma_phi == pytest.approx(np.radians(row[2]) * f("phi"))
    assert d.config.sigma_psi == pytest.approx(np.radians(row[3]) * f("psi"))
    assert d.config.sigma_kappa == pytest.approx(row[4] * f("kappa"))
    assert d.config.sigma_delta_d == pytest.approx(row[5] * f("delta_d"))
    # a record without the correlation (the shipped ones): the RMS as it is
    bare = traced.traced_javelin(setup, "4x4", {k: v for k, v in rec.items() if k != "correlation"})
    assert bare.config.sigma_phi == pytest.approx(np.radians(row[2]))
    s = traced.error_model_summary(rec)
    assert s["kind"] == "traced-measured" and s["sigmas"]["kappa_m"] == pytest.approx(row[4])
    assert traced.error_model_summary(None) == {"kind": "reported-crlb"}
    told = traced.error_model_summary(rec, d.config)["told_sigmas"]
    assert "told_sigmas" not in s and told["kappa_m"] == pytest.approx(d.config.sigma_kappa)
    assert told["psi_deg"] == pytest.approx(np.degrees(d.config.sigma_psi))
    with pytest.raises(TypeError, match="config"):
        traced.error_model_summary(rec, {"sigma_phi": 0.1})
    # the errors the traced channel gives are far above the reported CRLB of the image design
    assert s["sigmas"]["phi_deg"] > 0.1


#: a two-unit sweep of one drive each on a short route: every epoch counted
FEW = {"units": 2, "max_units": 2, "drives_per_unit": 1, "settle": 0.0}


def test_the_sweep_and_report_name_the_error_model(setup):
    rep = design.design_sweep(
        setup, ["4x4"], seed=0, mode="channel", n_epochs=3, traced_tracker="paths", **FEW
    )
    row = rep.rows[0]
    assert row.runs == 2 and row.error_p90_m is not None and np.isfinite(row.error_p90_m)
    j = rep.to_json()
    assert j["inputs"]["channel"] == "sionna"
    em = j["arrays"][0]["error_model"]
    assert em["kind"] == "traced-measured" and em["seed"] == traced.ERROR_SEED
    # seed 0 is the one the noise was chosen on: the report says so
    assert any("measured on this seed" in w for w in rep.warnings)
    assert "traced route, noise measured on seed 0" in rep.to_table()
    # the image channel's JSON carries neither
    img = design.design_sweep(
        design.DesignSetup.from_scenario(SCENARIO), ["4x4"], seed=1, mode="channel",
        n_epochs=2, **FEW,
    ).to_json()  # fmt: skip
    assert "channel" not in img["inputs"] and "error_model" not in img["arrays"][0]
    assert "traced_tracker" not in img["inputs"]
    assert j["inputs"]["traced_tracker"] == "paths"


def test_the_traced_bounds_are_those_of_the_told_sigmas(setup):
    """traced_bounds: the model has one diagonal block of the sigmas per existing path and no
    bias; the bound grows with the sigmas, tends to dead reckoning's (no radio) for huge ones,
    and learning the VUEs can only lose information."""
    from tunnelkit.design import drive_pcrlb
    from tunnelkit.tracking.javelin.designs import ours_coherent

    sig = {"phi": 0.05, "psi": 0.04, "kappa": 20.0, "d": 0.5}
    m, _ = tracedbounds.sigma_error_model(setup, "4x4", sig, epochs=np.arange(6))
    k, p = np.argwhere(m.exists)[0]
    block = m.cov[k, 4 * p : 4 * p + 4, 4 * p : 4 * p + 4]
    np.testing.assert_allclose(block, np.diag([0.05**2, 0.04**2, 400.0, 0.25]))
    ex4 = np.repeat(m.exists, 4, axis=1)
    assert np.all(np.isnan(m.cov[~(ex4[:, :, None] & ex4[:, None, :])]))
    assert np.all(m.bias[m.exists] == 0)

    def cfg(scale):
        return ours_coherent().with_(
            sigma_phi=0.05 * scale, sigma_psi=0.04 * scale, sigma_kappa=20.0 * scale,
            sigma_delta_d=0.5 * scale,
        ).config  # fmt: skip

    T = 6
    pc1, dr1 = tracedbounds.traced_bounds(setup, "4x4", cfg(1.0), T)
    pc3, _ = tracedbounds.traced_bounds(setup, "4x4", cfg(3.0), T)
    pch, _ = tracedbounds.traced_bounds(setup, "4x4", cfg(1e6), T)
    assert pc1.shape == (T,) and np.all(pc3 > pc1)
    np.testing.assert_allclose(dr1, pc1)  # no bias: the prediction is the posterior CRLB
    # the start's prior: a better entry fix, a lower bound; the default is the design's start
    pc_fine, _ = tracedbounds.traced_bounds(setup, "4x4", cfg(1.0), T, sigma_p0=0.1)
    assert np.all(pc_fine < pc1) and pc_fine[0] < 0.2 < pc1[0]
    np.testing.assert_allclose(
        tracedbounds.traced_bounds(setup, "4x4", cfg(1.0), T, sigma_p0=design.START_SIGMA_M)[0], pc1
    )
    # float epochs (whole numbers, as route_geometry takes them) give the same model
    mf, _ = tracedbounds.sigma_error_model(setup, "4x4", sig, epochs=np.arange(6.0))
    np.testing.assert_array_equal(mf.t, m.t)
    none = drive_pcrlb(setup, np.zeros((T, 2, 2)))
    np.testing.assert_allclose(pch, none, rtol=1e-6)
    assert np.all(pc1 < none)


def test_the_sweep_reports_the_bound_of_the_told_sigmas(setup):
    rec = traced.design_errors(setup, "4x4", n_epochs=3)
    d = traced.traced_javelin(setup, "4x4", rec)
    k = design.counted_epochs(setup.trajectory.t[:3], 0.0)
    for fix in (None, 0.1):  # the default entry fix and a better one: the bounds' prior follows
        kw = {"traced_tracker": "paths", **({} if fix is None else {"start_sigma": fix})}
        rep = design.design_sweep(setup, ["4x4"], seed=0, mode="channel", n_epochs=3, **FEW, **kw)
        row = rep.rows[0]
        _, drive = tracedbounds.traced_bounds(setup, "4x4", d.config, 3, sigma_p0=fix)
        # the told sigmas' posterior CRLB: a prediction of the traced tracker, not its bound
        assert row.pcrlb_rms_m is None and row.hybrid_bound_rms_m is None
        assert row.predicted_drive_rms_m == pytest.approx(np.sqrt(np.mean(drive[k] ** 2)))
        assert row.rmse_over_predicted_drive == pytest.approx(
            row.rmse_m / row.predicted_drive_rms_m
        )
        told = row.error_model["told_sigmas"]
        assert told["phi_deg"] == pytest.approx(np.degrees(d.config.sigma_phi))
        table = rep.to_table()
        assert "the tracker is told their long-run value" in table
        assert "posterior CRLB of the sigmas the tracker is told" in table
        assert f"{row.predicted_drive_rms_m:.3g} m, tracker RMSE / it" in table


def test_bad_input(setup):
    image = design.DesignSetup.from_scenario(SCENARIO)
    with pytest.raises(ValueError, match="setup"):
        traced.traced_route(image, "4x4")
    with pytest.raises(TypeError, match="setup"):
        traced.design_errors("italiano2026-straight", "4x4")
    with pytest.raises(TypeError, match="record"):
        traced.traced_javelin(setup, "4x4", {"no": "rows"})
    with pytest.raises(ValueError, match="record"):
        traced.traced_javelin(setup, "4x4", {"rows": [["all", 1, 0.0, 1.0, 1.0, 1.0, 0]]})
    with pytest.raises(TypeError, match="rng"):
        traced.traced_drive(traced.traced_route(setup, "4x4"), 3)
    with pytest.raises(ValueError, match="route"):
        traced.traced_drive(image.signal_route("4x4"), np.random.default_rng(0))
    cfg = traced.traced_javelin(setup, "4x4", {"rows": [["all", 1, 9.0, 8.0, 30.0, 1.0, 0]]}).config
    with pytest.raises(ValueError, match="sigmas"):
        tracedbounds.sigma_error_model(setup, "4x4", {"phi": 0.1, "psi": 0.1, "kappa": 1.0})
    with pytest.raises(ValueError, match="sigmas"):
        tracedbounds.sigma_error_model(
            setup, "4x4", {"phi": 0.0, "psi": 0.1, "kappa": 1.0, "d": 1.0}
        )
    with pytest.raises(TypeError, match="config"):
        tracedbounds.traced_bounds(setup, "4x4", {"sigma_phi": 0.1}, 2)
    with pytest.raises(ValueError, match=r"^T:"):
        tracedbounds.traced_bounds(setup, "4x4", cfg, 0)
    with pytest.raises(ValueError, match="sigma_p0"):
        tracedbounds.traced_bounds(setup, "4x4", cfg, 2, sigma_p0=0.0)
    names = ("sigma_phi", "sigma_psi", "sigma_kappa", "sigma_delta_d")
    told = {k: getattr(cfg, k) for k in names}
    with pytest.raises(ValueError, match=r"^config:"):
        tracedbounds.traced_bounds(setup, "4x4", SimpleNamespace(**{**told, "sigma_phi": 0.0}), 2)
    for bad in ("a", True, -1.0, np.nan):
        with pytest.raises((TypeError, ValueError), match=r"sigmas\['phi'\]"):
            tracedbounds.sigma_error_model(
                setup, "4x4", {"phi": bad, "psi": 0.1, "kappa": 1.0, "d": 1.0}
            )
    with pytest.raises(ValueError, match="error_models"):
        design.sweep_montecarlo(setup, ["4x4"], 1, 0, mode="channel", n_epochs=1,
                                error_models=lambda st, sp: None)  # fmt: skip
    imp = design.DesignImpairments(phase_error_deg=0.5)
    with pytest.raises(ValueError, match="impairments"):
        design.sweep_montecarlo(setup, ["4x4"], 1, 0, mode="channel", impairments=imp, n_epochs=1)


def test_the_paper_tunnels_records_ship_and_others_go_to_the_cache(tmp_path, monkeypatch):
    """The shipped records (data/rt/design) match the current scene; a record the repository
    does not ship lives in the ray-tracing cache."""
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    setup = design.DesignSetup.from_scenario(SCENARIO, channel="sionna")
    for label in ("4x4", "8x8", "10x10"):
        p = traced.design_errors_path(setup, label)
        assert p.parent.name == "design" and p.is_file()
        rec = traced.design_errors(setup, label, measure=False)  # provenance checked
        assert rec["array"] == label and rec["seed"] == traced.ERROR_SEED
    assert traced.design_errors_path(setup, "4x4", 3) == tmp_path / "design-errors" / (
        f"{SCENARIO}-4x4-T3.json"
    )


def test_variant_switches_the_channel_source_and_keeps_it_otherwise():
    """``DesignSetup.variant(channel=)`` used to validate the channel and drop it: a copy always
    came back with the original source. Now ``None`` keeps, ``"sionna"`` takes the scenario's
    ray-tracing settings, ``"image"`` goes back, and an unknown source is refused by name."""
    from tunnelkit import design

    base = design.DesignSetup.from_scenario("italiano2026-straight")
    assert base.channel == "image" and base.rt_settings is None
    rt = base.variant(channel="sionna")
    assert rt.channel == "sionna" and rt.rt_settings is not None
    want = design.DesignSetup.from_scenario("italiano2026-straight", channel="sionna")
    assert rt.rt_settings == want.rt_settings
    kept = rt.variant(bandwidth=50e6)
    assert kept.channel == "sionna" and kept.rt_settings == rt.rt_settings
    assert rt.variant(channel="image").channel == "image"
    with pytest.raises(ValueError, match=r"^channel"):
        base.variant(channel="raytrace")


def test_both_kinds_of_a_design_drive_come_from_one_extraction(setup, monkeypatch):
    """design_drive keeps the "ml-all" drive beside the "ml-traced" one: asked for the other
    kind of a drive it made, it drives nothing and gives what traced_drive gives."""
    ref = traced.traced_drive(traced.traced_route(setup, "4x4"), np.random.default_rng(31),
                              n_epochs=1)  # fmt: skip
    g = np.random.default_rng(31)
    _same_drive(traced.design_drive(setup, "4x4", g, n_epochs=1), ref["ml-traced"])
    end = g.bit_generator.state
    driven = []
    monkeypatch.setattr(traced, "traced_drive", lambda *a, **k: driven.append(1))
    g = np.random.default_rng(31)
    every = traced.design_drive(setup, "4x4", g, n_epochs=1, kind="ml-all")
    assert driven == [] and g.bit_generator.state == end
    _same_drive(every, ref["ml-all"])
    with pytest.raises(ValueError, match=r"^kind"):
        traced.design_drive(setup, "4x4", np.random.default_rng(31), n_epochs=1, kind="ml")


def test_kept_drives_go_to_another_process_and_are_tracked_there_without_driving(
    setup, monkeypatch
):
    """kept_drives lists what design_drive keeps for a setup; pickled and given to keep_drives
    for another setup object of the same scene (another process's), design_drive reads them:
    the same drive, the generator moved as driving moves it, nothing driven."""
    import pickle

    monkeypatch.setattr(traced, "_DRIVES", type(traced._DRIVES)())
    g = np.random.default_rng(41)
    first = traced.design_drive(setup, "4x4", g, n_epochs=1)
    end = g.bit_generator.state
    entries = pickle.loads(pickle.dumps(traced.kept_drives(setup)))
    assert len(entries) == 1 and set(entries[0][1]) == set(traced.DRIVE_KINDS)
    twin = design.DesignSetup.from_scenario(SCENARIO, channel="sionna")
    assert traced.kept_drives(twin) == []
    monkeypatch.setattr(traced, "_DRIVES", type(traced._DRIVES)())  # a fresh process
    monkeypatch.setattr(traced, "traced_drive", lambda *a, **k: pytest.fail("driven"))
    traced.keep_drives(twin, entries)
    g = np.random.default_rng(41)
    _same_drive(traced.design_drive(twin, "4x4", g, n_epochs=1), first)
    assert g.bit_generator.state == end
    other = design.DesignSetup.from_scenario("example-rectangular-28ghz", channel="sionna")
    with pytest.raises(ValueError, match=r"^entries: a drive of another route"):
        traced.keep_drives(other, entries)  # another scene's drives
    for bad in ([("4x4", None, "{}")], [(entries[0][0], {"ml": first}, end)], "drives"):
        with pytest.raises((TypeError, ValueError), match=r"^entries"):
            traced.keep_drives(twin, bad)
    with pytest.raises(ValueError, match=r"^setup"):
        traced.kept_drives(design.DesignSetup.from_scenario(SCENARIO))


def test_the_line_of_sight_survey_is_in_the_errors_record_and_its_table_is_its_rms(setup):
    """The errors' record carries the survey of the line of sight on the same drives (seed 0):
    one row per epoch with a path (measured elevation, azimuth error, elevation error), each the
    picked path's angles against the true line of sight of that drive; los_table with one bin
    is their RMS, by default LOS_BINS bins or fewer on a short survey."""
    from tunnelkit.design.los import LOS_WINDOW_M, los_errors
    from tunnelkit.runner import run_trials

    rec = traced.design_errors(setup, "4x4", n_epochs=2)
    rows = np.array(rec["los_rows"])
    assert rec["los_window_m"] == LOS_WINDOW_M
    assert rows.shape[1] == 3 and 2 <= rows.shape[0] <= 2 * traced.ERROR_RUNS
    assert np.all(np.abs(rows[:, 1]) <= np.pi) and np.all(np.abs(rows[:, 0]) <= np.pi / 2)
    # the same drives as the errors' rows: the survey's "ml-all" drives of seed 0
    route = traced.traced_route(setup, "4x4")
    drives = run_trials(lambda _i, rng: traced.traced_drive(route, rng, n_epochs=2)["ml-all"],
                        traced.ERROR_RUNS, traced.ERROR_SEED,
                        inputs=[None] * traced.ERROR_RUNS)  # fmt: skip
    np.testing.assert_allclose(rows, los_errors(drives))
    table = tracedlos.los_table(rec, bins=1)
    np.testing.assert_allclose(table.sigma_azimuth, [np.sqrt(np.mean(rows[:, 1] ** 2))])
    np.testing.assert_allclose(table.sigma_elevation, [np.sqrt(np.mean(rows[:, 2] ** 2))])
    short = min(tracedlos.LOS_BINS, rows.shape[0] // 2)
    assert tracedlos.los_table(rec).elevation.size == short
    with pytest.raises(TypeError, match=r"^record"):
        tracedlos.los_table({"no": "rows"})
    with pytest.raises(ValueError, match=r"^record: .*delete it to re-measure"):
        tracedlos.los_table({k: v for k, v in rec.items() if k != "los_rows"})
    with pytest.raises(ValueError, match=r"^record: los_rows"):
        tracedlos.los_table({**rec, "los_rows": [[0.1, 0.2]]})
    with pytest.raises(ValueError, match=r"^record\['los_rows'\]"):
        tracedlos.los_table({**rec, "los_rows": [[0.1, np.nan, 0.0]] * 4}, bins=1)
    with pytest.raises(ValueError, match=r"^record: a survey of at least 2"):
        tracedlos.los_table({**rec, "los_rows": [[0.1, 0.01, 0.0]]})
    # surveyed with another window than the tracker picks with; ragged or impossible rows
    with pytest.raises(ValueError, match=r"^record: .*picked within 0.6 m"):
        tracedlos.los_table({**rec, "los_window_m": 0.6})
    with pytest.raises(ValueError, match=r"^record: los_rows must be rows"):
        tracedlos.los_table({**rec, "los_rows": [[0.1, 0.2, 0.3], [0.1]]})
    with pytest.raises(ValueError, match=r"^record: los_rows hold an elevation beyond"):
        tracedlos.los_table({**rec, "los_rows": [[2.0, 0.01, 0.0]] * 4})
    with pytest.raises(ValueError, match=r"^bins: 50 bins"):
        tracedlos.los_table(rec, bins=50)
    # tied elevations: the default steps down to fewer bins instead of failing
    tied = {**rec, "los_rows": [[-0.1, 0.01, 0.02]] * 6 + [[-0.2, 0.02, 0.01]] * 2}
    assert tracedlos.los_table(tied).elevation.size < tracedlos.LOS_BINS


def test_the_line_of_sight_sweep_tracks_the_same_drives_told_its_table(setup):
    """The sweep with traced_tracker "los": the same drives, entry fixes and messages as the
    "paths" tracker's (dead reckoning identical), one path an epoch told its sigmas from the
    survey's table; its prediction is the told model's posterior CRLB (los_bounds), which with a
    table of one bin is drive_pcrlb of constant angle sigmas; the report names the tracker."""
    from tunnelkit.design import drive_pcrlb
    from tunnelkit.design.los import ElevationSigmas, los_angle_information
    from tunnelkit.tracking.javelin import ReportedNoise

    kw = {"seed": 0, "mode": "channel", "n_epochs": 3, "dead_reckoning": True, **FEW}
    paths = design.design_sweep(setup, ["4x4"], traced_tracker="paths", **kw).rows[0]
    rep = design.design_sweep(setup, ["4x4"], traced_tracker="los", **kw)
    los = rep.rows[0]
    # the default on the traced channel's channel route ("auto"): per array the tracker whose
    # told model predicts the smaller RMS over the route, and then that tracker's very row
    default = design.design_sweep(setup, ["4x4"], **kw)
    auto = default.rows[0]
    by = auto.error_model["chosen_by_predicted_rms_m"]
    assert default.to_json()["inputs"]["traced_tracker"] == "auto"
    assert auto.error_model["tracker"] == min(by, key=by.get)
    named = {"los": los, "paths": paths}[auto.error_model["tracker"]]
    assert (auto.rmse_m, auto.error_p90_m) == (named.rmse_m, named.error_p90_m)
    assert f"--traced-tracker auto chose {auto.error_model['tracker']}" in default.to_table()
    assert "chosen_by_predicted_rms_m" not in los.error_model
    # the predictions it compares: the two told models' posterior CRLBs over the route (here
    # too short to settle: every epoch), computed here on their own
    rec3 = traced.design_errors(setup, "4x4", n_epochs=3)
    cfg = traced.traced_javelin(setup, "4x4", rec3).config
    want = {
        "paths": tracedbounds.traced_bounds(setup, "4x4", cfg, 3)[1],
        "los": tracedbounds.los_bounds(setup, "4x4", tracedlos.los_table(rec3), 3)[1],
    }
    for name, drive in want.items():
        assert by[name] == pytest.approx(np.sqrt(np.mean(drive**2)), rel=1e-12), name
    # on its bound route, and on the image channel, the default is the paths tracker (no
    # survey asked for; "los" given by name there is refused: tests/test_design_los.py)
    bound = design.design_sweep(setup, ["4x4"], seed=0, units=0)
    assert bound.to_json()["inputs"]["traced_tracker"] is None  # no traced tracker runs
    assert los.dead_reckoning_rmse_m == pytest.approx(paths.dead_reckoning_rmse_m, rel=1e-12)
    em = los.error_model
    assert em["tracker"] == "los" and paths.error_model["tracker"] == "paths"
    assert em["los"]["bins"] == min(tracedlos.LOS_BINS, em["los"]["epochs"] // 2)
    assert rep.to_json()["inputs"]["traced_tracker"] == "los"
    assert "the line of sight alone (tracker los)" in rep.to_table()
    rec = traced.design_errors(setup, "4x4", n_epochs=3)
    table = tracedlos.los_table(rec)
    k = design.counted_epochs(setup.trajectory.t[:3], 0.0)
    _, drive = tracedbounds.los_bounds(setup, "4x4", table, 3)
    assert los.predicted_drive_rms_m == pytest.approx(np.sqrt(np.mean(drive[k] ** 2)))
    d = tracedlos.los_javelin(traced.traced_javelin(setup, "4x4", rec))
    with pytest.raises(TypeError, match=r"^design"):
        tracedlos.los_javelin(d)  # already reading reported covariances
    assert isinstance(d.noise, ReportedNoise)
    # the told drive: one path an epoch, its covariance the table's at its measured elevation
    every = traced.design_drive(setup, "4x4", np.random.default_rng(5), n_epochs=3, kind="ml-all")
    told = tracedlos.told_los(every, table, d.config)
    for ep in told.epochs:
        if ep is not None:
            saz, sel = table.at(ep.psi)
            assert len(ep) == 1 and told.reports_covariance
            np.testing.assert_allclose(np.diag(ep.cov[0])[:2], [saz[0] ** 2, sel[0] ** 2])
            assert ep.cov[0, 2, 2] == pytest.approx(d.config.sigma_kappa**2)
    # one bin: the constant sigmas' posterior CRLB
    one = ElevationSigmas(np.array([-0.1]), np.array([0.02]), np.array([0.03]))
    ue = setup.trajectory.position[:3]
    bs = setup.signal_route("4x4").arrays[0].origin
    ref = drive_pcrlb(setup, los_angle_information(ue, bs, 0.02, 0.03))
    np.testing.assert_allclose(tracedbounds.los_bounds(setup, "4x4", one, 3)[0], ref)
    with pytest.raises(TypeError, match=r"^table"):
        tracedbounds.los_bounds(setup, "4x4", {"elevation": [0.0]}, 3)
    with pytest.raises(TypeError, match=r"^los"):
        traced.error_model_summary(rec, d.config, {"bins": 4})


def test_auto_keeps_the_paths_tracker_where_its_prediction_is_smaller_or_no_survey(
    setup, monkeypatch
):
    """With "auto" and the line of sight's prediction the larger: the paths tracker, its drives
    ("ml-traced") and its row, to the digit; with a record that holds no survey: the paths
    tracker again, the reason in the row's error model and the table (an explicit "los" is
    refused there)."""
    from tunnelkit.design import montecarlo

    monkeypatch.setattr(montecarlo, "_PREPARED", type(montecarlo._PREPARED)())  # none kept
    kw = {"seed": 3, "mode": "channel", "n_epochs": 3, **FEW}
    paths = design.design_sweep(setup, ["4x4"], traced_tracker="paths", **kw).rows[0]
    real = tracedbounds.los_bounds

    def worse(*a, **k):  # the line of sight's told model predicting ten times the error
        pc, drive = real(*a, **k)
        return pc, 10 * drive

    monkeypatch.setattr(tracedbounds, "los_bounds", worse)
    kinds = []
    real_drive = traced.design_drive

    def spy(*a, kind="ml-traced", **k):
        kinds.append(kind)
        return real_drive(*a, kind=kind, **k)

    monkeypatch.setattr(traced, "design_drive", spy)
    auto = design.design_sweep(setup, ["4x4"], **kw)
    row = auto.rows[0]
    by = row.error_model["chosen_by_predicted_rms_m"]
    assert row.error_model["tracker"] == "paths" and by["los"] > by["paths"]
    assert set(kinds) == {"ml-traced"} and "los" not in row.error_model
    assert (row.rmse_m, row.error_p90_m) == (paths.rmse_m, paths.error_p90_m)
    assert "--traced-tracker auto chose paths" in auto.to_table()
    # a record without the survey: auto keeps paths and says why; "los" refuses it
    monkeypatch.setattr(tracedbounds, "los_bounds", real)
    monkeypatch.setattr(montecarlo, "_PREPARED", type(montecarlo._PREPARED)())
    rec = traced.design_errors(setup, "4x4", n_epochs=3)
    bare = {k: v for k, v in rec.items() if k != "los_rows"}
    monkeypatch.setattr(traced, "design_errors", lambda *a, **k: bare)
    row = design.design_sweep(setup, ["4x4"], **kw).rows[0]
    assert row.error_model["tracker"] == "paths" and "los_rows" in row.error_model["auto_fallback"]
    assert list(row.error_model["chosen_by_predicted_rms_m"]) == ["paths"]
    bad = design.design_sweep(setup, ["4x4"], traced_tracker="los", **kw).rows[0]
    assert bad.status == "error" and "los_rows" in bad.reason


def test_the_direct_sweep_is_the_direct_drive_from_the_drawn_fix(setup):
    """traced_tracker "direct": each drive is traceddirect.direct_drive on the design's traced
    route (the line of sight's JAVELIN fed the direct fix, told design_table: the array's
    shipped survey times SURVEY_SCALE, with DESIGN_OPTIONS), started from the open-sky fix drawn
    from a generator spawned before the drive's; dead reckoning is the same tracker on that
    drive's messages; the prediction beside it is the told model's posterior CRLB; the report
    names the tracker and its told sigmas."""
    from tunnelkit.design.arrayjob import ArrayJob, SweepTrial
    from tunnelkit.design.directsurvey import SURVEY_SCALE, design_table, survey_record
    from tunnelkit.design.traceddirect import DESIGN_OPTIONS, direct_drive
    from tunnelkit.tracking.javelin import ReportedNoise, draw_start

    kw = {"seed": 0, "mode": "channel", "n_epochs": 3, "dead_reckoning": True, **FEW}
    rep = design.design_sweep(setup, ["4x4"], traced_tracker="direct", **kw)
    row = rep.rows[0]
    em = row.error_model
    assert em["tracker"] == "direct" and em["direct"]["options"] == DESIGN_OPTIONS
    table = design_table(setup.name, "4x4")
    assert em["direct"]["told_deg"] == table.as_dict()
    rec = survey_record(setup.name, "4x4")  # shipped: the told table is the survey's times 2
    assert em["direct"]["survey"]["command"] == rec["command"] and rec["array"] == "4x4"
    np.testing.assert_allclose(np.degrees(table.sigma_azimuth),
                               SURVEY_SCALE * np.asarray(rec["table_deg"]["sigma_azimuth"]))  # fmt: skip
    assert "a survey of" in rep.to_table() and f"times {SURVEY_SCALE:g}" in rep.to_table()
    assert set(em["told_sigmas"]) == {"kappa_m", "delta_d_m"}  # the angles are the table's
    assert rep.to_json()["inputs"]["traced_tracker"] == "direct"
    assert "the direct fit's line of sight (tracker direct" in rep.to_table()
    assert np.isfinite(row.rmse_m) and np.isfinite(row.dead_reckoning_rmse_m)
    k = design.counted_epochs(setup.trajectory.t[:3], 0.0)
    _, drive = tracedbounds.los_bounds(setup, "4x4", table, 3)
    assert row.predicted_drive_rms_m == pytest.approx(np.sqrt(np.mean(drive[k] ** 2)))
    # one drive of the sweep's trial, against direct_drive called by hand on the same draws
    prep = ArrayJob(setup, None, "channel", 3, False, None, traced_tracker="direct")(
        design.parse_array("4x4")
    )
    assert isinstance(prep.design.noise, ReportedNoise)
    assert prep.direct.as_dict() == table.as_dict()
    trial = SweepTrial(setup, "channel", 3, dead_reckoning=True)
    got = trial((prep, 7), np.random.default_rng(11))
    rng, g = np.random.default_rng(11).spawn(2)
    route = traced.traced_route(setup, "4x4")
    p0 = draw_start(route.trajectory.position[0], trial.start_sigma, g, 0.05)
    out = direct_drive(route, rng, prep.design, None, table, n_epochs=3, start=p0,
                       start_sigma=trial.start_sigma, start_height_sigma=0.05,
                       **DESIGN_OPTIONS)  # fmt: skip
    for j, name in enumerate(("direct", "dead reckoning")):
        want = np.linalg.norm(out.estimates[name][:, :2] - out.truth[:, :2], axis=1)
        np.testing.assert_array_equal(got[j], want)
    assert got.shape == (2, 3) and np.all(np.isfinite(got))


def test_the_direct_drive_is_cut_to_the_route_as_every_drive(setup, monkeypatch):
    """A sweep's n_epochs beyond the route drives the whole route (as the other trackers'
    drives), and None drives it all: direct_drive is never asked for more epochs than it has."""
    from tunnelkit.design import traceddirect
    from tunnelkit.design.arrayjob import Prepared, SweepTrial
    from tunnelkit.design.directsurvey import design_table

    asked = []

    class Stop(Exception):
        pass

    def recording(route, rng, design_, eq1_table, table, **kw):
        asked.append(kw["n_epochs"])
        raise Stop

    monkeypatch.setattr(traceddirect, "direct_drive", recording)
    prep = Prepared(design.parse_array("4x4"), None, None, np.zeros(1), None, None,
                    direct=design_table(setup.name, "4x4"))  # fmt: skip
    n = len(setup.trajectory)
    for n_epochs in (n + 5, n, 2, None):
        with pytest.raises(Stop):
            SweepTrial(setup, "channel", n_epochs)((prep, 0), np.random.default_rng(0))
    assert asked == [n, n, 2, None]
