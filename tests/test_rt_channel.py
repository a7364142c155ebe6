"""The ray-traced channel source: settings, per-element synthesis, snapshot, cache, switch.

The tests marked with Sionna need the ``rt`` extra (``make test`` installs it); like
``test_rt_crossval`` they fail without it unless ``TUNNELKIT_SKIP_RT=1``.
"""

from __future__ import annotations

import dataclasses
import json
import os
import sys
import warnings

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import channel, propagation, rt
from tunnelkit.arrays import make_array
from tunnelkit.rt.elements import ElementPaths, element_tensor
from tunnelkit.rt.settings import MATERIALS, RTSettings
from tunnelkit.scenarios import ScenarioError
from tunnelkit.schema import tunnel3d
from tunnelkit.signal_route import SignalRoute
from tunnelkit.signal_route.raytraced import tensor_snapshot

SKIP_RT = os.environ.get("TUNNELKIT_SKIP_RT") == "1"
needs_sionna = pytest.mark.skipif(SKIP_RT, reason="TUNNELKIT_SKIP_RT=1")


# --- settings and scenario fields ----------------------------------------------------------------
@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"scattering_coefficient": 1.2}, "scattering_coefficient"),
        ({"scattering_coefficient": -0.1}, "scattering_coefficient"),
        ({"metal_scattering_coefficient": 2.0}, "metal_scattering_coefficient"),
        ({"road_material": "tarmac"}, "road_material"),
        ({"wall_material": "concrete "}, "wall_material"),
        ({"scattering_pattern": "gaussian"}, "scattering_pattern"),
        ({"max_depth": 0}, "max_depth"),
        ({"antenna_pattern": "dipole"}, "antenna_pattern"),
    ],
)
def test_settings_refuse_bad_input_naming_the_parameter(kw, name):
    with pytest.raises(ValueError, match=name):
        RTSettings(**kw)


def test_settings_materials_by_kind():
    st = RTSettings(scattering_coefficient=0.4, metal_scattering_coefficient=0.1)
    assert st.material_for("wall") == ("concrete", "concrete", 0.3, 0.4)
    assert st.material_for("road") == ("asphalt", "very_dry_ground", 0.05, 0.4)
    assert st.material_for("rrm") == ("metal", "metal", 0.01, 0.1)
    assert st.diffuse and not RTSettings(scattering_coefficient=0.0).diffuse
    assert st.fingerprint() != RTSettings().fingerprint()
    assert RTSettings().fingerprint() == RTSettings().fingerprint()


def test_schema_matches_settings():
    """The scenario's [raytracing] keys have RTSettings' names, defaults and material names."""
    table = tunnel3d.RAYTRACING
    fields = {f.name: f.default for f in dataclasses.fields(RTSettings)}
    assert {k.name: k.default for k in table.keys} == fields
    assert set(tunnel3d.RT_MATERIALS) == set(MATERIALS)


def test_material_bands_are_the_tracers_and_refuse_a_carrier_outside():
    """MATERIAL_BANDS against Sionna RT's own ITU-R P.2040 table (each material's widest band
    starting at its lowest frequency); a material is refused at a carrier where its model is not
    defined, naming the setting, and the 28 GHz presets' roads are modelled at 28 GHz."""
    itu = pytest.importorskip("sionna.rt.radio_materials.itu")
    from tunnelkit.rt.settings import MATERIAL_BANDS

    assert set(MATERIAL_BANDS) == set(MATERIALS)
    for name, (itu_name, _) in MATERIALS.items():
        bands = sorted(itu.ITU_MATERIALS_PROPERTIES[itu_name])
        lo, hi = bands[0]
        assert MATERIAL_BANDS[name] == (lo * 1e9, hi * 1e9), name
    RTSettings().check_carrier(5.9e9)
    with pytest.raises(ValueError, match=r"^road_material: 'asphalt' .* 28 GHz"):
        RTSettings().check_carrier(28e9)
    with pytest.raises(ValueError, match=r"^wall_material: 'brick' .* 60 GHz"):
        RTSettings(wall_material="brick").check_carrier(60e9)
    RTSettings(road_material="asphalt_concrete").check_carrier(28e9)
    sc = tk.load_scenario("italiano2026-straight")
    tun, arrays = sc.tunnel(), propagation.scenario_arrays(sc)
    with pytest.raises(ValueError, match=r"^road_material"):
        rt.RayTracedChannel(tun, arrays, sc.trajectory(tun), channel.SRSConfig(fc=28e9),
                            RTSettings())  # fmt: skip
    for name in ("example-rectangular-28ghz", "mont-blanc-28ghz"):
        sc = tk.load_scenario(name)
        rt.RTSettings.from_scenario(sc).check_carrier(channel.SRSConfig.from_scenario(sc).fc)


def _scenario_with(tmp_path, text: str):
    src = tk.load_scenario("italiano2026-straight").path.read_text()
    path = tmp_path / "rt.toml"
    path.write_text(src + "\n[raytracing]\n" + text + "\n")
    return tk.load_scenario(path)


def test_scenario_raytracing_section(tmp_path):
    sc = _scenario_with(tmp_path, 'scattering_coefficient = 0.5\nscattering_pattern = "directive"')
    st = RTSettings.from_scenario(sc)
    assert st.scattering_coefficient == 0.5 and st.scattering_pattern == "directive"
    assert st.road_material == "asphalt" and st.max_depth == 2
    assert RTSettings.from_scenario(tk.load_scenario("italiano2026-straight")) == RTSettings()
    with pytest.raises(ScenarioError, match="scattering_coefficient"):
        _scenario_with(tmp_path, "scattering_coefficient = 1.5")
    with pytest.raises(ScenarioError, match="road_material"):
        _scenario_with(tmp_path, 'road_material = "tarmac"')


# --- synthesis -----------------------------------------------------------------------------------
def _random_paths(rng, M=3, P=7):
    return ElementPaths(
        tau=rng.uniform(5e-8, 3e-7, (M, P)),
        gain=rng.standard_normal((M, P)) + 1j * rng.standard_normal((M, P)),
        doppler=rng.uniform(-500, 500, (M, P)),
        valid=rng.random((M, P)) < 0.8,
        order=rng.integers(0, 3, (M, P)),
        diffuse=rng.random((M, P)) < 0.3,
        first_object=np.zeros((M, P), np.int64),
    )


def test_element_tensor_against_the_sum():
    """The recurrence over tones equals the path-by-path sum of the module's formula (the tones
    counted from the centre tone, where the carrier is)."""
    rng = np.random.default_rng(1)
    ep = _random_paths(rng)
    df, T0, nf, nt = 240e3, 3.57e-5, 50, 5
    H = element_tensor(ep, df, nf, T0, nt)
    s, k = np.arange(nf) - 0.5 * (nf - 1), np.arange(nt)
    brute = np.zeros_like(H)
    for m in range(ep.M):
        for p in np.flatnonzero(ep.valid[m]):
            brute[m] += (
                np.conj(ep.gain[m, p])
                * np.exp(-2j * np.pi * s * df * ep.tau[m, p])[:, None]
                * np.exp(2j * np.pi * k * T0 * ep.doppler[m, p])[None, :]
            )
    np.testing.assert_allclose(H, brute, rtol=0, atol=1e-12 * np.abs(brute).max())
    sel = ep.mask("diffuse")
    np.testing.assert_allclose(
        element_tensor(ep, df, nf, T0, nt, select=sel)
        + element_tensor(ep, df, nf, T0, nt, select=~sel),
        H,
        atol=1e-12 * np.abs(H).max(),
    )
    assert ep.power() == pytest.approx(np.sum(np.abs(ep.gain) ** 2 * ep.valid) / ep.M)
    with pytest.raises(ValueError, match="kind"):
        ep.mask("diffuse-ish")
    with pytest.raises(ValueError, match="gain"):
        ElementPaths(
            ep.tau, ep.gain[:, :2], ep.doppler, ep.valid, ep.order, ep.diffuse, ep.first_object
        )


@needs_sionna  # finufft comes with the rt extra
@pytest.mark.parametrize(("nf", "nt", "P"), [(410, 12, 3000), (51, 5, 200), (1, 1, 80)])
def test_element_tensor_nufft_against_the_direct_sum(nf, nt, P):
    """The NUFFT synthesis equals the path-by-path sum to the tolerance asked (relative error
    <= 1e-6 at eps = 1e-9, the default), for even and odd tone and symbol counts, with delays
    past one period of the tone spacing (folded) and gains over 80 dB of dynamic range."""
    rng = np.random.default_rng(7)
    M = 3
    ep = ElementPaths(
        tau=rng.uniform(2e-8, 6e-6, (M, P)),
        gain=(rng.standard_normal((M, P)) + 1j * rng.standard_normal((M, P)))
        * 10 ** rng.uniform(-4, 0, (M, P)),
        doppler=rng.uniform(-800, 800, (M, P)),
        valid=rng.random((M, P)) < 0.9,
        order=rng.integers(0, 3, (M, P)),
        diffuse=rng.random((M, P)) < 0.5,
        first_object=np.zeros((M, P), np.int64),
    )
    df, T0 = 240e3, 3.5677e-5
    ref = element_tensor(ep, df, nf, T0, nt, method="direct")
    for eps, tol in ((1e-9, 1e-6), (1e-12, 1e-9)):
        H = element_tensor(ep, df, nf, T0, nt, method="nufft", eps=eps)
        assert np.linalg.norm(H - ref) <= tol * np.linalg.norm(ref)
        assert np.abs(H - ref).max() <= tol * np.abs(ref).max()
    # a loose tolerance is visibly loose: the test can tell the two apart
    H = element_tensor(ep, df, nf, T0, nt, method="nufft", eps=1e-3)
    if nf * nt > 1:
        assert np.linalg.norm(H - ref) > 1e-9 * np.linalg.norm(ref)
    sel = ep.mask("diffuse")
    auto = element_tensor(ep, df, nf, T0, nt, select=sel)  # auto: nufft above 64 paths
    np.testing.assert_allclose(
        auto,
        element_tensor(ep, df, nf, T0, nt, select=sel, method="direct"),
        rtol=0,
        atol=1e-6 * np.abs(auto).max(),
    )


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"method": "fft"}, "method"),
        ({"eps": 0.0}, "eps"),
        ({"eps": 0.1}, "eps"),
        ({"tone_spacing": -1.0}, "tone_spacing"),
        ({"symbol_period": 0.0}, "symbol_period"),
    ],
)
def test_element_tensor_refuses_bad_input(kw, name):
    ep = _random_paths(np.random.default_rng(0))
    args = {"tone_spacing": 240e3, "n_tones": 8, "symbol_period": 3.57e-5, "n_symbols": 2} | kw
    with pytest.raises(ValueError, match=name):
        element_tensor(ep, **args)


def test_element_tensor_without_finufft(monkeypatch):
    """Without finufft, "auto" sums directly and "nufft" is an install hint."""
    ep = _random_paths(np.random.default_rng(2), P=100)
    ref = element_tensor(ep, 240e3, 16, 3.57e-5, 3, method="direct")
    monkeypatch.setitem(sys.modules, "finufft", None)
    np.testing.assert_array_equal(element_tensor(ep, 240e3, 16, 3.57e-5, 3), ref)
    with pytest.raises(ImportError, match="finufft"):
        element_tensor(ep, 240e3, 16, 3.57e-5, 3, method="nufft")


def test_tensor_snapshot_equals_synthesize():
    """Unit-power tensor + clock-bias ramp + noise = eq. 1 with that clock bias (same draws)."""
    sc = tk.load_scenario("italiano2026-straight")
    tun, cfg = sc.tunnel(), channel.SRSConfig.from_scenario(sc)
    traj = sc.trajectory(tun)
    arr = propagation.select_array(propagation.scenario_arrays(sc), traj.position[3])
    paths = propagation.trace_paths(tun, arr, traj.position[3], traj.velocity[3], fc=cfg.fc)
    H0 = channel.channel_tensor(paths, cfg) / np.sqrt(cfg.tx_power)
    a = channel.synthesize(paths, cfg, np.random.default_rng(5), clock_bias=37e-9)
    b = tensor_snapshot(H0, cfg, np.random.default_rng(5), paths=paths, clock_bias=37e-9)
    np.testing.assert_allclose(b.H, a.H, rtol=0, atol=1e-9 * np.abs(a.H).max())
    assert b.clock_bias == a.clock_bias and b.noise_power == a.noise_power
    # the clock bias drawn from rng as synthesize draws it
    a = channel.synthesize(paths, cfg, np.random.default_rng(6))
    b = tensor_snapshot(H0, cfg, np.random.default_rng(6), paths=paths)
    assert a.clock_bias == b.clock_bias
    with pytest.raises(ValueError, match="H0"):
        tensor_snapshot(H0[0], cfg, np.random.default_rng(0))


# --- the switch ----------------------------------------------------------------------------------
def test_route_channel_switch_validates():
    route = SignalRoute.from_scenario("italiano2026-straight")
    assert route.channel == "image" and route.raytraced is None
    with pytest.raises(TypeError, match="raytraced"):
        dataclasses.replace(route, raytraced="sionna")
    with pytest.raises(ValueError, match="channel"):
        SignalRoute.from_scenario("italiano2026-straight", channel="ray")
    rs = SignalRoute.from_scenario("italiano2026-straight", channel="sionna")
    assert isinstance(rs.raytraced, rt.RayTracedChannel)
    with pytest.raises(ValueError, match="dmc"):
        dataclasses.replace(rs, impairments=channel.Impairments(dmc=channel.DiffuseSpec(0.1)))
    # a model option of one channel on the other is refused naming both
    with pytest.raises(ValueError, match=r"model: 'srnf'.*channel='image'.*channel='sionna'"):
        rs.with_options(model="srnf")
    with pytest.raises(ValueError, match=r"diffuse_floor: .*channel='sionna'"):
        route.with_options(diffuse_floor=True)


def test_reproduce_refuses_a_channel_the_target_lacks():
    from tunnelkit.reproduce import run, targets

    assert targets()["javelin-table1"].channels == ("image", "sionna")
    with pytest.raises(ValueError, match="channel"):
        run("jiang-crlb", runs=1, channel="sionna")


def test_missing_sionna_is_an_install_hint(monkeypatch, tmp_path):
    sc = tk.load_scenario("italiano2026-straight")
    tun = sc.tunnel()
    rc = rt.RayTracedChannel(
        tun,
        propagation.scenario_arrays(sc),
        sc.trajectory(tun),
        channel.SRSConfig.from_scenario(sc),
        cache_dir=tmp_path,
    )
    monkeypatch.setattr(rt, "_checked", False)
    monkeypatch.setitem(sys.modules, "drjit", None)
    with pytest.raises(rt.RTUnavailableError, match=r"pip install -e '\.\[rt\]'"):
        rc.epoch(0)


# --- with Sionna ---------------------------------------------------------------------------------
def _small(sc, n=4):
    """An n x n array at the preset's mount and orientation (every element inside the tunnel)."""
    a = propagation.scenario_arrays(sc)[1]
    return make_array(
        n,
        n,
        fc=sc.get("radio.fc"),
        azimuth=0.0,
        elevation=np.radians(-30.0),
        origin=a.origin,
        name="+x",
    )


@needs_sionna
def test_sionna_tensor_matches_image_method_first_order():
    """Diffuse off, first order only: per path traced at every element, Sionna's tensor (in eq.
    1's convention, conjugated) is the image method's with spatial_wideband on, up to one
    complex constant per path (Sionna's polarimetric ITU coefficient vs the TE Fresnel one):
    residual below 2e-3 for the LoS and 5e-2 for reflections (amplitude 1/d_m and the
    reflection coefficient vary over the aperture; the image method holds them at element 0's),
    over the whole band. Without the conjugation the residual is of order 1; with the tones
    measured from tone 0 instead of the carrier's centre tone, the LoS's is several times
    larger."""
    sc = tk.load_scenario("italiano2026-straight")
    tun, cfg = sc.tunnel(), channel.SRSConfig.from_scenario(sc)
    traj = sc.trajectory(tun)
    arr = _small(sc)
    eng = rt.engine_for(tun, fc=cfg.fc)
    eng.apply_settings(RTSettings(scattering_coefficient=0.0, max_depth=1, samples_per_src=100_000))
    k = 12
    ue, vel = traj.position[k], traj.velocity[k]
    ep = eng.trace_elements(arr, ue, vel)
    assert not ep.diffuse[ep.valid].any() and ep.order[ep.valid].max() <= 1
    img = propagation.trace_paths(tun, arr, ue, vel, fc=cfg.fc)
    nf, nt = cfg.n_tones, 4  # every tone: the wideband term grows with the band
    checked = 0
    for p in img:
        sel = np.zeros_like(ep.valid)
        for m, j in zip(*np.nonzero(ep.valid), strict=True):
            name, kind = eng.surface_of(ep.first_object[m, j])
            sel[m, j] = kind == "los" if p.kind == "los" else name == p.surface
        if not np.all(sel.sum(axis=1) == 1):
            continue  # the specular point slides off the surface across the aperture
        b = channel.channel_tensor(
            [p], cfg, n_tones=nf, n_symbols=nt, spatial_wideband=True
        ).ravel()
        # the tones measured from tone 0 instead of the carrier's centre tone (the tensor
        # before the carrier was centred): the same paths, each element's phase off by
        # k0 delta_lm s_c Df / fc
        edge = np.exp(1j * np.pi * (nf - 1) * cfg.tone_spacing * ep.tau)
        res = {}
        for name, e in (("eq. 1", ep), ("unconjugated", dataclasses.replace(ep, gain=np.conj(ep.gain))),
                        ("tone 0", dataclasses.replace(ep, gain=ep.gain * edge))):  # fmt: skip
            h = element_tensor(e, cfg.tone_spacing, nf, cfg.symbol_period, nt, select=sel).ravel()
            c = np.vdot(b, h) / np.vdot(b, b)
            res[name] = np.linalg.norm(h - c * b) / np.linalg.norm(h)
        assert res["eq. 1"] < (2e-3 if p.kind == "los" else 5e-2), (p.kind, p.surface, res)
        assert res["unconjugated"] > 0.5, (p.kind, p.surface, res)
        if p.kind == "los":
            assert res["tone 0"] > 3 * res["eq. 1"], res
        checked += 1
    assert checked >= 3  # LoS, road and a wall at least


@needs_sionna
def test_cache_reuses_and_rebuilds(tmp_path):
    sc = tk.load_scenario("italiano2026-straight")
    tun, cfg = sc.tunnel(), channel.SRSConfig.from_scenario(sc)
    arrays = [_small(sc, 2)]
    traj = sc.trajectory(tun)
    st = RTSettings(samples_per_src=2000)
    args = (tun, arrays, traj, cfg, st)
    rc = rt.RayTracedChannel(*args, label="t", cache_dir=tmp_path)
    e = rc.epoch(20)
    d = tmp_path / "t" / "rrms"
    assert (d / "epoch-020.npz").is_file() and (d / "meta.json").is_file()
    assert e["H"].shape == (4, cfg.n_tones, cfg.n_symbols) and e["count"]["los"] == 1.0
    assert e["power"]["diffuse"] > 0 and e["count"]["diffuse"] > 0
    name, H = rc.tensor(20)
    _, H_nolos = rc.tensor(20, los=False)
    assert name == "+x" and np.abs(H - H_nolos).max() > 0
    # a second channel with the same key reads the file: never traces
    rc2 = rt.RayTracedChannel(*args, label="t", cache_dir=tmp_path)
    rc2.trace = None  # any trace would fail
    np.testing.assert_array_equal(rc2.epoch(20)["H"], e["H"])
    # a cache written for another scene version is detected and rebuilt
    meta = json.loads((d / "meta.json").read_text())
    meta["scene"] = "0" * 64
    (d / "meta.json").write_text(json.dumps(meta))
    rc3 = rt.RayTracedChannel(*args, label="t", cache_dir=tmp_path)
    with pytest.warns(UserWarning, match="another scene"):
        rc3.directory()
    assert not (d / "epoch-020.npz").exists()
    assert json.loads((d / "meta.json").read_text()) == rc3.key()
    # other settings: another key
    assert (
        rt.RayTracedChannel(tun, arrays, traj, cfg, RTSettings(samples_per_src=3000)).key()
        != rc3.key()
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc3.epoch(20)


def test_design_channel_plumbing(capsys):
    from tunnelkit import design
    from tunnelkit.cli import main

    setup = design.DesignSetup.from_scenario("italiano2026-straight", channel="sionna")
    route = setup.signal_route("4x4")
    assert route.channel == "sionna" and route.raytraced.label.endswith("design-4x4")
    assert route.raytraced.arrays[0].M == 16
    assert (
        design.DesignSetup.from_scenario("italiano2026-straight").signal_route("4x4").raytraced
        is None
    )
    with pytest.raises(ValueError, match="channel"):
        design.DesignSetup.from_scenario("italiano2026-straight", channel="rt")
    assert main(["design", "italiano2026-straight", "--arrays", "4x4", "--channel", "sionna"]) == 2
    assert "--mode channel" in capsys.readouterr().err


@needs_sionna
def test_element_pattern_is_oriented_along_the_boresight():
    """With the 3GPP TR 38.901 element (8 dBi, 65 deg beamwidth) each element receiver is turned
    to the array's boresight: the LoS power over the isotropic one is the pattern's gain in the
    LoS direction seen in the boresight frame (within 1 dB: polarisation), not that of another
    orientation (the down-tilt's sign alone moves it by about 2 dB)."""
    sc = tk.load_scenario("italiano2026-straight")
    tun, cfg = sc.tunnel(), channel.SRSConfig.from_scenario(sc)
    traj = sc.trajectory(tun)
    arr = _small(sc, 2)
    k = 20
    ue, vel = traj.position[k], traj.velocity[k]
    eng = rt.engine_for(tun, fc=cfg.fc)
    los = {}
    for pattern in ("iso", "tr38901"):
        eng.apply_settings(
            RTSettings(
                scattering_coefficient=0.0,
                max_depth=1,
                samples_per_src=2000,
                antenna_pattern=pattern,
            )
        )
        ep = eng.trace_elements(arr, ue, vel)
        los[pattern] = np.sum(np.abs(ep.gain) ** 2 * ep.mask("los"))
    measured = 10 * np.log10(los["tr38901"] / los["iso"])

    def expected(b):
        yaw, pitch = np.arctan2(b[1], b[0]), -np.arcsin(b[2])
        rz = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
        ry = np.array(
            [[np.cos(pitch), 0, np.sin(pitch)], [0, 1, 0], [-np.sin(pitch), 0, np.cos(pitch)]]
        )
        R = rz @ ry  # columns: the receiver's local x (boresight), y, z in the world
        u = (ue - arr.world.mean(axis=0)) / np.linalg.norm(ue - arr.world.mean(axis=0))
        x, y, z = R.T @ u
        th, ph = np.degrees(np.arccos(z)), np.degrees(np.arctan2(y, x))
        return 8.0 - min(min(12 * ((th - 90) / 65) ** 2, 30) + min(12 * (ph / 65) ** 2, 30), 30)

    b = arr.boresight
    assert abs(measured - expected(b)) < 1.0, (measured, expected(b))
    up = np.array([b[0], b[1], -b[2]])  # the same boresight tilted up
    assert abs(measured - expected(up)) > 1.0


# --- bad input without Sionna: a cache of another scene version ------------------------------------
def test_cache_of_another_scene_version_is_rebuilt_without_sionna(tmp_path):
    """The key hashes the exported scene: a tunnel changed under the same label (a road marking
    moved) is detected on the directory check and the cache emptied, before any trace; a
    corrupt meta.json is treated the same way; the same scene keeps its files."""
    sc = tk.load_scenario("italiano2026-straight")
    tun, cfg = sc.tunnel(), channel.SRSConfig.from_scenario(sc)
    arrays, traj = propagation.scenario_arrays(sc), sc.trajectory(tun)
    rc = rt.RayTracedChannel(tun, arrays, traj, cfg, label="t", cache_dir=tmp_path)
    d = rc.directory()
    (d / "epoch-000.npz").write_bytes(b"old")
    same = rt.RayTracedChannel(tun, arrays, traj, cfg, label="t", cache_dir=tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert same.directory() == d and (d / "epoch-000.npz").is_file()
    plate = tun.plates[0]
    moved = dataclasses.replace(
        tun,
        plates=(
            dataclasses.replace(plate, corner=plate.corner + np.array([1.0, 0.0, 0.0])),
            *tun.plates[1:],
        ),
    )
    other = rt.RayTracedChannel(moved, arrays, traj, cfg, label="t", cache_dir=tmp_path)
    assert other.key()["scene"] != rc.key()["scene"]
    with pytest.warns(UserWarning, match="another scene"):
        assert other.directory() == d
    assert not (d / "epoch-000.npz").exists()
    assert json.loads((d / "meta.json").read_text()) == other.key()
    (d / "epoch-001.npz").write_bytes(b"old")
    (d / "meta.json").write_text("{not json")
    again = rt.RayTracedChannel(moved, arrays, traj, cfg, label="t", cache_dir=tmp_path)
    with pytest.warns(UserWarning, match="another scene"):
        again.directory()
    assert not (d / "epoch-001.npz").exists()


def test_scenario_refuses_unknown_material_for_each_surface(tmp_path):
    for key in ("wall_material", "road_material", "rrm_material"):
        with pytest.raises(ScenarioError, match=key):
            _scenario_with(tmp_path, f'{key} = "unobtainium"')
    with pytest.raises(ScenarioError, match="metal_scattering_coefficient"):
        _scenario_with(tmp_path, "metal_scattering_coefficient = -0.5")
