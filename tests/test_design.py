"""tunnelkit.design: the position error bound against a brute-force Fisher information, the
vectorised route tracer against trace_paths, SR-NF mismatch against the traced path lengths."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from tunnelkit import channel, design, extraction, propagation
from tunnelkit.constants import C

SCEN = "italiano2026-straight"


@pytest.fixture(scope="module")
def setup():
    return design.DesignSetup.from_scenario(SCEN)


def _paths(setup, arr, ue, vel):
    ps = propagation.trace_paths(setup.tunnel, arr, ue, vel, fc=setup.fc, kinds=setup.kinds)
    return {p.surface or "LoS": p for p in ps}


def brute_force_peb(
    setup, spec, k, *, curvature=True, clock_bias="unknown", height_known=True, h=1e-5
):
    """PEB from finite differences of the synthesised tensor (channel.channel_tensor).

    Columns: d H / d (x, y) by re-tracing the paths from a perturbed UE (central differences),
    d H / d (c b) by re-synthesising with a perturbed clock bias, per path d H / d (Re a, Im a,
    mu_t) and, without curvature, d H / d(radius) at fixed delay. FIM = 2 / N0 Re(J^H J).
    """
    cfg = setup.config
    traj = setup.trajectory
    ue, vel = traj.position[k], traj.velocity[k]
    arr = propagation.select_array(setup.arrays(spec), ue)
    base = _paths(setup, arr, ue, vel)
    names = list(base)
    H0 = lambda ps, b=0.0: channel.channel_tensor(ps, cfg, clock_bias=b)  # noqa: E731
    cols = []
    n_pos = 2 if height_known else 3
    for i in range(n_pos):
        e = np.zeros(3)
        e[i] = h
        pp, pm = _paths(setup, arr, ue + e, vel), _paths(setup, arr, ue - e, vel)
        assert list(pp) == names and list(pm) == names
        cols.append((H0([pp[n] for n in names]) - H0([pm[n] for n in names])) / (2 * h))
    ps = [base[n] for n in names]
    if clock_bias == "unknown":
        cols.append((H0(ps, h / C) - H0(ps, -h / C)) / (2 * h))
    kk = np.arange(cfg.n_symbols)[None, None, :]
    s = np.arange(cfg.n_tones)[None, :, None]
    for p in ps:
        Hl = H0([p])
        a = np.sqrt(cfg.tx_power) * p.gain
        cols += [Hl / a, 1j * Hl / a, 1j * kk * Hl]
        if not curvature:
            u = (p.source - arr.origin) / p.length
            moved = replace(p, lengths=np.linalg.norm(p.source + h * u - arr.world, axis=1))
            back = replace(p, lengths=np.linalg.norm(p.source - h * u - arr.world, axis=1))
            dH = (H0([moved]) - H0([back])) / (2 * h)
            # keep the delay fixed: remove what the moved reference length did to tau
            dH -= Hl * (-2j * np.pi * cfg.tone_spacing * s / C)
            cols.append(dH)
    J = np.stack([c.ravel() for c in cols], axis=1)
    F = 2.0 / cfg.noise_power * (J.conj().T @ J).real
    sc = 1 / np.sqrt(np.diag(F))
    cov = sc[:, None] * np.linalg.inv(sc[:, None] * F * sc[None, :]) * sc[None, :]
    return float(np.sqrt(np.trace(cov[:n_pos, :n_pos])))


@pytest.mark.parametrize(
    ("spec", "k", "curvature", "clock", "height_known"),
    [
        ("4x4", 5, True, "unknown", True),
        ("4x4", 20, True, "known", True),
        ("4x4", 12, False, "unknown", True),
        ("3x5", 25, True, "unknown", True),
        ("4x4", 16, True, "unknown", False),
        ("4x4", 16, False, "known", False),
    ],
)
def test_peb_matches_brute_force_fisher_information(setup, spec, k, curvature, clock, height_known):
    kw = {"curvature": curvature, "clock_bias": clock, "height_known": height_known}
    closed = design.route_bounds(setup, spec, epochs=[k], **kw)
    brute = brute_force_peb(setup, spec, k, **kw)
    # central differences with h = 10 um on a phase slope of 2 pi / lambda: ~1e-6 relative
    assert closed.peb[0] == pytest.approx(brute, rel=1e-4)


def test_peb_variants_are_ordered(setup):
    full = design.route_bounds(setup, "8x8")
    no_curv = design.route_bounds(setup, "8x8", curvature=False)
    no_rrm = design.route_bounds(setup, "8x8", markings=False)
    known = design.route_bounds(setup, "8x8", clock_bias="known")
    # dropping information can only raise the bound (nuisances, fewer paths)
    assert np.all(no_curv.peb >= full.peb * (1 - 1e-9))
    assert np.all(no_rrm.peb >= full.peb * (1 - 1e-9))
    assert np.all(known.peb <= full.peb * (1 + 1e-9))
    assert np.all(np.isfinite(full.peb))
    assert no_rrm.used[:, np.array(no_rrm.kinds) == "rrm"].sum() == 0


def test_eta_fisher_information_matches_crlb_paths(setup):
    """The joint eq. 1 FIM inside route_bounds gives crlb_paths' delay bounds."""
    spec = design.parse_array("4x4")
    cfg = setup.config
    k = 8
    g = design.trace_route(
        setup.tunnel,
        setup.arrays(spec),
        setup.trajectory.position[[k]],
        setup.trajectory.velocity[[k]],
        fc=cfg.fc,
    )
    j = np.flatnonzero(g.exists[0])
    src = (g.source[0, j] - g.origin[0]) @ g.rotation[0]
    d0 = np.linalg.norm(src, axis=1)
    alpha = np.sqrt(cfg.tx_power) * g.gain[0, j]
    mu_f = -2 * np.pi * cfg.tone_spacing * d0 / C
    mu_t = 2 * np.pi * cfg.symbol_period * g.doppler[0, j]
    pos = spec.local(cfg.fc)
    G = design.bounds._fim_eta(
        src[None],
        pos,
        alpha[None],
        mu_f[None],
        mu_t[None],
        np.ones((1, j.size), bool),
        cfg.fc,
        cfg.n_tones,
        cfg.n_symbols,
        cfg.noise_power,
    )[0]
    sc = 1 / np.sqrt(np.diag(G))
    cov = sc[:, None] * np.linalg.inv(sc[:, None] * G * sc[None, :]) * sc[None, :]
    ref = extraction.crlb_paths(
        alpha, src, pos, mu_f, mu_t, cfg.fc, cfg.n_tones, cfg.n_symbols, cfg.noise_power
    )
    idx = 7 * np.arange(j.size)
    np.testing.assert_allclose(np.sqrt(cov[idx + 2, idx + 2]), ref["mu_f"], rtol=1e-6)
    np.testing.assert_allclose(np.sqrt(cov[idx + 3, idx + 3]), ref["mu_t"], rtol=1e-6)
    src_cov = np.stack([cov[i + 4 : i + 7, i + 4 : i + 7] for i in idx])
    np.testing.assert_allclose(src_cov, ref["source_cov"], rtol=1e-5, atol=1e-18)


def test_trace_route_matches_trace_paths(setup):
    arrs = setup.arrays("10x10")
    traj = setup.trajectory
    g = design.trace_route(setup.tunnel, arrs, traj.position, traj.velocity, fc=setup.fc)
    for t in range(len(traj)):
        arr = propagation.select_array(arrs, traj.position[t])
        ps = propagation.trace_paths(
            setup.tunnel, arr, traj.position[t], traj.velocity[t], fc=setup.fc
        )
        j = np.flatnonzero(g.exists[t])
        assert [g.names[i] for i in j] == sorted(
            (p.surface or "LoS" for p in ps), key=[g.names[i] for i in j].index
        )
        assert len(j) == len(ps)
        by_name = {p.surface or "LoS": p for p in ps}
        for i in j:
            p = by_name[g.names[i]]
            np.testing.assert_allclose(g.source[t, i], p.source, atol=1e-12)
            np.testing.assert_allclose(g.point[t, i], p.point, atol=1e-9)
            assert abs(g.gain[t, i] - p.gain) <= 1e-12 * abs(p.gain)
            assert g.doppler[t, i] == pytest.approx(p.doppler, abs=1e-9)
        np.testing.assert_allclose(g.origin[t], arr.origin)


def test_srnf_mismatch_matches_path_lengths(setup):
    """Exact mismatch = 2 pi / lambda max |delta_exact - delta_srnf| from the traced lengths."""
    spec = "8x8"
    b = design.route_bounds(setup, spec)
    arrs = setup.arrays(spec)
    lam = C / setup.fc
    traj = setup.trajectory
    for t in (0, 10, 28):
        arr = propagation.select_array(arrs, traj.position[t])
        ps = propagation.trace_paths(
            setup.tunnel, arr, traj.position[t], traj.velocity[t], fc=setup.fc
        )
        names = list(design.trace_route(setup.tunnel, arrs, traj.position[[t]], fc=setup.fc).names)
        for p in ps:
            want = 2 * np.pi / lam * np.max(np.abs(p.delta("exact") - p.delta("srnf")))
            got = b.mismatch[t, names.index(p.surface or "LoS")]
            assert got == pytest.approx(want, rel=1e-6, abs=1e-9)
    # the ceiling 0.2 m above the array binds: SR-NF fails there from 4x4 upwards
    assert b.surface_validity()["ceiling"] == 0.0
    assert b.surface_validity()["road"] > 0.5


def test_peb_shrinks_with_array_size(setup):
    med = [np.median(design.route_bounds(setup, s).peb) for s in ("4x4", "8x8", "10x10")]
    assert med[0] > med[1] > med[2]


def test_parse_array():
    assert design.parse_array("8x8") == design.ArraySpec(8, 8)
    assert design.parse_array(" 4 x 16 ").n_elements == 64
    assert design.parse_array("16").label == "16"
    for bad in ("8y8", "x8", "", "8x", "1x1", "0x4"):
        with pytest.raises(ValueError, match=r"^(spec|arrays): "):
            design.parse_array(bad)
    with pytest.raises(TypeError, match=r"^spec: "):
        design.parse_array(8)


def test_bad_setups(setup):
    with pytest.raises(ValueError, match="arrays: the 32x32 array"):
        setup.arrays("32x32")
    with pytest.raises(ValueError, match="arrays"):
        setup.arrays("400x400")
    with pytest.raises(ValueError, match="mount"):
        design.DesignSetup.from_scenario(SCEN, mount_height=5.5)
    with pytest.raises(ValueError, match="fc"):
        design.DesignSetup.from_scenario(SCEN, fc=0.0)
    with pytest.raises(ValueError, match="bandwidth"):
        design.DesignSetup.from_scenario(SCEN, bandwidth=-1.0)
    with pytest.raises(ValueError, match="target"):
        design.design_sweep(setup, ["4x4"], target=0.0)
    with pytest.raises(ValueError, match="clock_bias"):
        design.route_bounds(setup, "4x4", clock_bias="maybe")


def test_overrides_change_the_radio(setup):
    s28 = design.DesignSetup.from_scenario(SCEN, fc=28e9, bandwidth=400e6, tilt_deg=10.0)
    assert s28.config.fc == 28e9 and s28.config.bandwidth == 400e6
    assert s28.config.n_rb == int(400e6 // (12 * s28.config.scs))
    assert all(m.elevation == pytest.approx(-np.radians(10.0)) for m in s28.mounts)


def test_every_public_name_resolves():
    import importlib

    import tunnelkit as tk

    for name in design.__all__:
        assert getattr(tk.design, name) is getattr(design, name), name
    # every submodule's public names are re-exported by the package
    for sub in ("setup", "geometry", "bounds", "report", "montecarlo", "verdict", "intervals"):
        mod = importlib.import_module(f"tunnelkit.design.{sub}")
        for name in mod.__all__:
            assert name in design.__all__ and getattr(design, name) is getattr(mod, name), name
