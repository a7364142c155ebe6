"""The direct fit (tunnelkit.extraction.direct.fit): the image maps against the traced sources, the tied
atoms against eq. 1's true parameters, the fit on its own model's tensor (exact without noise, at
its Cramer-Rao bound with it) and its flag."""

from __future__ import annotations

import dataclasses
import os

import numpy as np
import pytest

from tunnelkit.arrays import ArrayGeometry
from tunnelkit.constants import C
from tunnelkit.extraction import ml_truth
from tunnelkit.extraction.direct.fit import DirectProblem, direct_fix, image_maps
from tunnelkit.extraction.direct.visibility import predicted_model, visible_second_order
from tunnelkit.extraction.numerics import spatial_phase
from tunnelkit.propagation import SECOND_ORDER, trace_paths
from tunnelkit.signal_route import SignalRoute

NF, NT = 48, 4  # a cut of the tensor: the fits are three parameters whatever its size


@pytest.fixture(scope="module")
def route():
    return SignalRoute.from_scenario("italiano2026-straight")


def _model(route, k, n2=4):
    arr = route.paths(k)[0]
    ue, vel = route.trajectory.position[k], route.trajectory.velocity[k]
    paths, masks, _ = predicted_model(route, arr, ue, vel, n2)
    return arr, ue, vel, paths, masks


@pytest.mark.parametrize("k", [0, 9, 20, 28])
def test_image_maps_give_every_traced_source(route, k):
    _, ue, _, paths, _ = _model(route, k)
    assert any(p.kind == "reflection2" for p in paths)
    R, t = image_maps(route.tunnel, paths)
    np.testing.assert_allclose(R @ ue + t, [p.source for p in paths], atol=1e-9)
    np.testing.assert_allclose(R @ np.swapaxes(R, 1, 2), np.tile(np.eye(3), (len(paths), 1, 1)),
                               atol=1e-12)  # fmt: skip


@pytest.mark.parametrize("k", [3, 25])
def test_tied_atoms_are_eq1s_true_parameters(route, k):
    """Every atom's parameters at the true position are eq. 1's true ones, the Doppler too with
    a velocity that has a sideways and a vertical part (the mirrors flip them per surface)."""
    arr, ue, vel, _, _ = _model(route, k)
    vel = vel + np.array([0.0, 1.5, 0.3])
    paths, masks, _ = predicted_model(route, arr, ue, vel, 64)
    H = np.ones((arr.M, NF, NT), complex)
    prob = DirectProblem(H, arr, route.config, masks, image_maps(route.tunnel, paths), ue[2], vel)
    b = 1.7
    theta, mu_f, mu_t = prob.atoms(np.r_[ue[:2], b])
    th, mf, mt = ml_truth(paths, arr, route.config)
    assert len({round(float(v), 9) for v in mt}) > 2  # the mirrors give different Dopplers
    np.testing.assert_allclose(theta, th, rtol=1e-10, atol=1e-13)
    np.testing.assert_allclose(mu_f, mf - 2 * np.pi * route.config.tone_spacing * b / C, rtol=1e-10)
    np.testing.assert_allclose(mu_t, mt, rtol=1e-8, atol=1e-14)
    speed = float(np.linalg.norm(vel))
    np.testing.assert_allclose(prob.atoms(np.r_[ue[:2], b, speed])[2], mt, rtol=1e-8, atol=1e-14)


def _tensor(prob, x, gains):
    """The direct model's own tensor at ``x`` with ``gains`` (masks applied)."""
    theta, mu_f, mu_t = prob.atoms(x)
    a = np.exp(1j * spatial_phase(theta, prob.pos, prob.k0)[0]) * prob.mask * gains
    F = np.exp(1j * prob.s * mu_f[None, :])
    T = np.exp(1j * prob.kk * mu_t[None, :])
    return np.einsum("ml,sl,kl->msk", a, F, T)


def _setup(route, k, seed):
    arr, ue, vel, paths, masks = _model(route, k)
    rng = np.random.default_rng(seed)
    maps = image_maps(route.tunnel, paths)
    gains = np.array([abs(p.gain) for p in paths]) * np.exp(2j * np.pi * rng.random(len(paths)))
    shell = DirectProblem(np.ones((arr.M, NF, NT), complex), arr, route.config, masks, maps,
                          ue[2], vel)  # fmt: skip
    x = np.r_[ue[:2], 0.4]
    return arr, ue, vel, shell, x, gains, rng


@pytest.mark.parametrize("k", [6, 22])
def test_fit_recovers_its_own_model(route, k):
    """The tensor of the model itself (masks and paths of the true position, the UE at 4.1 m/s
    where the message says 4.3): from a start 0.3 m off, the tied fit lands on the truth, the
    speed included; the whole fix from the true position too, and a gate closer than it moved
    flags it."""
    arr, ue, _, shell, x, gains, _ = _setup(route, k, 1)
    told = 4.3 * shell.heading
    x4 = np.r_[x, 4.1]

    def problem(H):
        return DirectProblem(H, arr, route.config, shell.mask, (shell.R, shell.t), ue[2], told)

    start = np.r_[ue[0] + 0.3, ue[1] - 0.2, x[2] + 0.2]
    f = problem(_tensor(shell, np.r_[x, 4.3], gains)).fit_tied(start)  # speed as told
    assert f["converged"] and f["residual"] < 1e-12
    np.testing.assert_allclose(f["x"], x, atol=1e-6)
    prob = problem(_tensor(shell, x4, gains))
    f = prob.fit_tied(np.r_[start, 4.3])
    assert f["converged"] and f["residual"] < 1e-12
    np.testing.assert_allclose(f["x"], x4, atol=1e-6)
    fix = direct_fix(route, arr, prob.H, ue, told)
    assert fix.ok and fix.residual < 1e-10
    np.testing.assert_allclose(np.r_[fix.position[:2], fix.clock_bias, fix.speed], x4, atol=1e-5)
    assert not direct_fix(route, arr, prob.H, ue + np.array([0.02, 0.0, 0.0]), told, gate=1e-3).ok


def test_unmodelled_share_is_what_the_model_lacks(route):
    """On the model's own tensor with noise the fix's residual beyond the noise is about zero
    (the noise's spread, a few parts in 10^5 here); with an interference the model cannot
    absorb (white, 5 % of the signal's power, 0.4 % noise) it is that share within 1e-3 (its
    sample power over 19,200 cells spreads by about 4e-4; without the noise's share subtracted
    both would be 4e-3 off)."""
    from tunnelkit.channel import ChannelSnapshot
    from tunnelkit.design.traceddirect import unmodelled_share

    arr, ue, vel, shell, x, gains, rng = _setup(route, 12, 7)
    H0 = _tensor(shell, x, gains)
    p0 = float(np.mean(np.abs(H0) ** 2))
    sigma2 = 4e-3 * p0

    def white(power):
        z = rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape)
        return np.sqrt(power / 2) * z

    told = np.linalg.norm(vel) * shell.heading
    for extra, want in ((0.0, 0.0), (0.05, 0.05 / (1.0 + 0.05 + 4e-3))):
        H = H0 + white(sigma2) + (white(extra * p0) if extra else 0.0)
        fix = direct_fix(route, arr, H, ue, told, speed=False)
        share = unmodelled_share(
            fix.residual, ChannelSnapshot(H, sigma2, 0.0, "exact", (), route.config)
        )
        assert fix.ok and abs(share - want) < 1e-3, (share, want)
    with pytest.raises(ValueError, match=r"^residual"):
        unmodelled_share(1.5, ChannelSnapshot(H0, sigma2, 0.0, "exact", (), route.config))
    with pytest.raises(TypeError, match=r"^snap"):
        unmodelled_share(0.1, H0)


def _crlb(shell, x, gains, sigma2):
    """The bound of (x, y, b) with the complex gains unknown: the Fisher information of the real
    parameters from central differences of the model tensor, the gains' block Schur-eliminated."""
    cols = []
    for i in range(3):
        e = np.zeros(3)
        e[i] = 1e-5
        cols.append(((_tensor(shell, x + e, gains) - _tensor(shell, x - e, gains)) / 2e-5).ravel())
    for j in range(len(gains)):
        g = np.zeros(len(gains), complex)
        g[j] = 1.0
        unit = _tensor(shell, x, g).ravel()
        cols += [unit, 1j * unit]
    J = np.column_stack(cols)
    F = 2.0 / sigma2 * (J.conj().T @ J).real
    return np.sqrt(np.diag(np.linalg.inv(F))[:3])


def test_fit_is_at_its_bound_with_noise(route):
    """Noise 30 dB below the line of sight's power per cell: the tied fit's RMSE over 40 draws
    (started 5 cm off) lies within the Monte-Carlo spread of its Cramer-Rao bound in x, y and the
    clock bias."""
    arr, ue, vel, shell, x, gains, rng = _setup(route, 14, 5)
    H0 = _tensor(shell, x, gains)
    sigma2 = abs(gains[0]) ** 2 * 1e-3
    bound = _crlb(shell, x, gains, sigma2)
    err = []
    for _ in range(40):
        noise = rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape)
        prob = DirectProblem(H0 + np.sqrt(sigma2 / 2) * noise, arr, route.config, shell.mask,
                             (shell.R, shell.t), ue[2], vel)  # fmt: skip
        f = prob.fit_tied(x + np.r_[0.05 * rng.standard_normal(2), 0.0])
        assert f["converged"]
        err.append(f["x"] - x)
    rmse = np.sqrt(np.mean(np.square(err), axis=0))
    # 40 draws: the RMSE of an efficient estimator is within ~25 % of its bound (chi-square, 40 dof)
    assert np.all(rmse < 1.3 * bound), (rmse, bound)
    assert np.all(rmse > 0.7 * bound), (rmse, bound)


def _diffuse_tensor(shell, ue, rng, delay_m, share):
    """A diffuse atom: a delay ``delay_m`` [m] past the line of sight's, a small Doppler, a free
    complex gain on every element, ``share`` of the line of sight's power per element."""
    _, mu_f, mu_t = shell.atoms(np.r_[ue[:2], 0.4])
    nu = np.array([mu_f[0] - 2 * np.pi * shell.srs.tone_spacing * delay_m / C, mu_t[0] + 0.01])
    u = rng.standard_normal(shell.M) + 1j * rng.standard_normal(shell.M)
    return nu, np.sqrt(share / 2) * np.einsum(
        "m,s,k->msk", u, np.exp(1j * shell.s[:, 0] * nu[0]), np.exp(1j * shell.kk[:, 0] * nu[1])
    )


def test_diffuse_gains_are_least_squares(route):
    """The concentrated cost with diffuse atoms equals the least-squares fit over the explicit
    columns (every tied atom, every diffuse atom on every element), and the model is its fit."""
    arr, ue, vel, shell, x, gains, rng = _setup(route, 9, 11)
    nu, D = _diffuse_tensor(shell, ue, rng, 0.6, 0.1)
    H = _tensor(shell, x, gains) + D + 0.05 * (rng.standard_normal(D.shape) + 0j)
    prob = DirectProblem(H, arr, route.config, shell.mask, (shell.R, shell.t), ue[2], vel,
                         diffuse=2)  # fmt: skip
    xd = np.r_[x + np.array([0.03, -0.02, 0.1]), nu, nu + np.array([0.02, -0.005])]
    cols = [_tensor(shell, x + np.array([0.03, -0.02, 0.1]), np.eye(len(gains))[j]).ravel()
            for j in range(len(gains))]  # fmt: skip
    for f, t in (nu, nu + np.array([0.02, -0.005])):
        for m in range(prob.M):
            e = np.zeros(prob.M)
            e[m] = 1.0
            cols.append(np.einsum("m,s,k->msk", e, np.exp(1j * prob.s[:, 0] * f),
                                  np.exp(1j * prob.kk[:, 0] * t)).ravel())  # fmt: skip
    A = np.column_stack(cols)
    c = np.linalg.lstsq(A, H.ravel(), rcond=None)[0]
    want = float(np.sum(np.abs(H.ravel() - A @ c) ** 2))
    np.testing.assert_allclose(prob.cost(xd), want, rtol=1e-8)
    np.testing.assert_allclose(prob.model(xd).ravel(), A @ c, atol=1e-9 * np.abs(H).max())


def test_diffuse_drop_on_noise_is_chi_square(route):
    """Under white noise alone, one diffuse atom at a fixed delay takes N0 / 2 chi-square(2 M)
    from the cost (200 draws: the mean and variance of 2 drop / N0 within 5 sigma of 2 M and
    4 M; the tied atoms overlap its columns without taking degrees of freedom)."""
    arr, ue, vel, shell, x, gains, rng = _setup(route, 9, 13)
    nu, _ = _diffuse_tensor(shell, ue, rng, 1.5, 0.0)
    H0 = _tensor(shell, x, gains)
    n0 = 0.01
    stat = []
    for _ in range(200):
        H = H0 + np.sqrt(n0 / 2) * (
            rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape)
        )
        p0 = DirectProblem(H, arr, route.config, shell.mask, (shell.R, shell.t), ue[2], vel)
        stat.append(2.0 * (p0.cost(x) - p0.with_diffuse(1).cost(np.r_[x, nu])) / n0)
    M = arr.M
    assert abs(np.mean(stat) - 2 * M) < 5 * np.sqrt(4 * M / 200)
    assert abs(np.var(stat) - 4 * M) < 5 * 4 * M * np.sqrt(2 / 199)


def test_diffuse_admission_rate_on_noise(route, monkeypatch):
    """The whole admission step (start on the grid, the fit moving the atom, the test) on the
    model's tensor with noise alone, the nominal false alarm raised to 0.2 so that 40 draws can
    see it: at most 15 admitted (binomial: a true rate of 0.2 exceeds it with probability about
    0.003; 2 of 60 were admitted when it was written). Counting only the Nf Nt resolution cells
    admitted 68 % at a nominal 0.1."""
    import tunnelkit.extraction.direct.fit as direct

    monkeypatch.setattr(direct, "DIFFUSE_FALSE_ALARM", 0.2)
    arr, ue, vel, shell, x, gains, rng = _setup(route, 9, 23)
    H0 = _tensor(shell, x, gains)
    n0 = abs(gains[0]) ** 2 * 1e-3
    admitted = 0
    for _ in range(40):
        H = H0 + np.sqrt(n0 / 2) * (
            rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape)
        )
        admitted += direct_fix(
            route, arr, H, ue, vel, speed=False, diffuse=1, noise_power=n0
        ).diffuse
    assert admitted <= 15, admitted


def test_direct_fix_admits_the_diffuse_atom_it_needs(route):
    """The model's tensor plus a diffuse atom 0.6 m past the line of sight (20 % of its power per
    element) and noise: the white fit is pulled off the truth; with at most two diffuse atoms the
    fix admits one and lands within 3 cm (0.3-1.7 cm over nine seeds: the atom's free gains take
    part of the line of sight's information) and at least 5 times closer than the white fit. On
    the model's tensor with noise alone no atom passes the test (10 draws); the fix is then the
    white fit's (the same code path: what is tested is that nothing is admitted)."""
    arr, ue, vel, shell, x, gains, rng = _setup(route, 9, 17)
    _, D = _diffuse_tensor(shell, ue, rng, 0.6, 0.2 * abs(gains[0]) ** 2)
    H0 = _tensor(shell, x, gains)
    n0 = abs(gains[0]) ** 2 * 1e-3

    def noisy():
        return np.sqrt(n0 / 2) * (
            rng.standard_normal(H0.shape) + 1j * rng.standard_normal(H0.shape)
        )

    H = H0 + D + noisy()
    white = direct_fix(route, arr, H, ue, vel, speed=False)
    fix = direct_fix(route, arr, H, ue, vel, speed=False, diffuse=2, noise_power=n0)
    err = lambda f: float(np.hypot(*(f.position[:2] - x[:2])))  # noqa: E731
    print(f"white fit {err(white):.4f} m, with diffuse atoms {err(fix):.5f} m ({fix.diffuse})")
    assert fix.ok and fix.diffuse >= 1 and err(fix) < 0.03, (fix, err(white))
    assert err(white) > 5 * err(fix)
    for _ in range(10):
        H = H0 + noisy()
        white = direct_fix(route, arr, H, ue, vel, speed=False)
        fix = direct_fix(route, arr, H, ue, vel, speed=False, diffuse=2, noise_power=n0)
        assert fix.diffuse == 0 and fix.ok
        np.testing.assert_array_equal(fix.position, white.position)


def test_unconverged_diffuse_fit_is_never_returned(route, monkeypatch):
    """A diffuse atom's fit that does not converge is dropped: the fix is the last converged
    model's (here the white fit's, which the same tensor admits an atom to when it converges)."""
    arr, ue, vel, shell, x, gains, rng = _setup(route, 9, 19)
    _, D = _diffuse_tensor(shell, ue, rng, 0.6, 0.2 * abs(gains[0]) ** 2)
    n0 = abs(gains[0]) ** 2 * 1e-3
    H = _tensor(shell, x, gains) + D
    H = H + np.sqrt(n0 / 2) * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))
    kw = {"speed": False, "noise_power": n0}
    assert direct_fix(route, arr, H, ue, vel, diffuse=1, **kw).diffuse == 1
    white = direct_fix(route, arr, H, ue, vel, **kw)
    real, calls = DirectProblem.fit_tied, []

    def unconverged(self, x0, **k):
        out = real(self, x0, **k)
        calls.append(self.diffuse)
        return {**out, "converged": out["converged"] and not self.diffuse}

    monkeypatch.setattr(DirectProblem, "fit_tied", unconverged)
    fix = direct_fix(route, arr, H, ue, vel, diffuse=1, **kw)
    assert calls.count(1) == 1 and fix.diffuse == 0 and fix.ok
    np.testing.assert_array_equal(fix.position, white.position)


def test_diffuse_tried_only_above_the_tied_fits_unmodelled_share(route):
    """``diffuse_above``: the atom is tried where the tied fit leaves more than that share beyond
    the noise and not where it leaves less; not tried, the fix is the tied fit's."""
    arr, ue, vel, shell, x, gains, rng = _setup(route, 9, 17)
    _, D = _diffuse_tensor(shell, ue, rng, 0.6, 0.2 * abs(gains[0]) ** 2)
    n0 = abs(gains[0]) ** 2 * 1e-3
    H = _tensor(shell, x, gains) + D
    H = H + np.sqrt(n0 / 2) * (rng.standard_normal(H.shape) + 1j * rng.standard_normal(H.shape))
    kw = {"speed": False, "noise_power": n0, "diffuse": 1}
    tied = direct_fix(route, arr, H, ue, vel, speed=False)
    share = tied.residual - n0 * H.size / float(np.sum(np.abs(H) ** 2))
    assert 0.01 < share < 0.5, share  # the atom leaves a clear misfit to the tied fit
    assert direct_fix(route, arr, H, ue, vel, diffuse_above=0.99 * share, **kw).diffuse == 1
    above = direct_fix(route, arr, H, ue, vel, diffuse_above=1.01 * share, **kw)
    assert above.diffuse == 0
    np.testing.assert_array_equal(above.position, tied.position)
    for bad in (-0.1, 1.0, np.nan):
        with pytest.raises(ValueError, match=r"^diffuse_above"):
            direct_fix(route, arr, H, ue, vel, diffuse_above=bad, **kw)
    with pytest.raises(ValueError, match=r"^diffuse_above.*without"):
        direct_fix(route, arr, H, ue, vel, diffuse_above=0.1)


def test_refusals_name_the_parameter(route):
    arr, ue, vel, shell, x, gains, _ = _setup(route, 10, 2)
    H = _tensor(shell, x, gains)
    with pytest.raises(ValueError, match=r"^prediction"):
        direct_fix(route, arr, H, ue[:2], vel)
    with pytest.raises(ValueError, match=r"^gate"):
        direct_fix(route, arr, H, ue, vel, gate=0.0)
    with pytest.raises(ValueError, match=r"^H"):
        direct_fix(route, arr, H[:, :, 0], ue, vel)
    with pytest.raises(ValueError, match=r"^x"):
        shell.atoms(np.r_[ue[:2]])
    with pytest.raises(ValueError, match=r"^x0"):
        shell.fit_tied(np.r_[ue, 0.0, 1.0])
    with pytest.raises(TypeError, match=r"^speed"):
        direct_fix(route, arr, H, ue, vel, speed="yes")
    with pytest.raises(ValueError, match=r"^noise_power"):
        direct_fix(route, arr, H, ue, vel, diffuse=1)
    with pytest.raises(ValueError, match=r"^diffuse"):
        direct_fix(route, arr, H, ue, vel, diffuse=5, noise_power=1.0)
    with pytest.raises(ValueError, match=r"^x.*diffuse"):
        shell.with_diffuse(1).cost(x)
    with pytest.raises(ValueError, match=r"^diffuse"):
        shell.with_diffuse(5)
    with pytest.raises(ValueError, match=r"^diffuse"):
        DirectProblem(H, arr, route.config, shell.mask, (shell.R, shell.t), ue[2], vel, diffuse=-1)
    for bad in (0.0, -1.0, np.nan, 1e3 * float(np.mean(np.abs(H) ** 2))):
        with pytest.raises(ValueError, match=r"^noise_power"):
            direct_fix(route, arr, H, ue, vel, diffuse=1, noise_power=bad)
    from tunnelkit.extraction.direct.fit import diffuse_threshold

    with pytest.raises(ValueError, match=r"^M"):
        diffuse_threshold(1, NF, NT)
    with pytest.raises(ValueError, match=r"^nt"):
        diffuse_threshold(arr.M, NF, 10**6)


SKIP_RT = os.environ.get("TUNNELKIT_SKIP_RT") == "1"


@pytest.mark.skipif(SKIP_RT, reason="TUNNELKIT_SKIP_RT=1")
def test_direct_drive_tiny_traced_case(tmp_path, monkeypatch):
    """Three epochs of the 4 x 4 on the traced channel: every tracker gives a finite track, dead
    reckoning is JAVELIN's own run on the same messages with no measurement (the loop steps as
    Javelin.run does, midpoint included), and the errors fed are recorded per epoch."""
    from tunnelkit.design.los import ElevationSigmas
    from tunnelkit.design.traceddirect import TRACKERS, direct_drive
    from tunnelkit.reproduce.javelin_traced import los_design
    from tunnelkit.studies.attribution import scenario_with_array
    from tunnelkit.tracking.javelin import run_javelin

    sc = scenario_with_array("italiano2026-straight", (4, 4))
    route = SignalRoute.from_scenario(sc, channel="sionna", cache_dir=str(tmp_path))
    table = ElevationSigmas(np.zeros(1), np.radians([1.0]), np.radians([1.0]))
    design = los_design()
    import tunnelkit.design.traceddirect as dt

    starts = []

    def recording(route_, arr, H, prediction, velocity, **kw):
        starts.append(np.array(prediction))
        return direct_fix(route_, arr, H, prediction, velocity, **kw)

    monkeypatch.setattr(dt, "direct_fix", recording)
    out = direct_drive(route, np.random.default_rng(4), design, table, table, speed_sigma=0.1,
                       n_epochs=3)  # fmt: skip
    assert set(out.estimates) == set(TRACKERS)
    assert all(np.all(np.isfinite(x)) and x.shape == (3, 3) for x in out.estimates.values())
    # every fit starts at the direct tracker's prediction, not at the truth
    assert len(starts) == 3 and all(
        np.any(p != t) for p, t in zip(starts[1:], route.trajectory.position[1:3], strict=True)
    )
    traj = route.trajectory
    vel = traj.velocity[:3]
    truth = np.linalg.norm(vel[:, :2], axis=1), np.arctan2(vel[:, 1], vel[:, 0])
    speed, heading = traj.odometry.draw(traj.t[:3], *truth, np.random.default_rng(4))
    d = design.with_(base_station=tuple(float(v) for v in route.arrays[0].origin),
                     sigma_p0_ue=0.1, sigma_p0_height=None)  # fmt: skip
    run = run_javelin([None] * 3, speed, heading, float(traj.t[1] - traj.t[0]), traj.position[0], d)
    np.testing.assert_allclose(out.estimates["dead reckoning"], run.estimates, atol=1e-12)
    assert out.dropped["direct"] < 3 and out.speed_errors.size >= 1
    assert not np.allclose(out.estimates["direct"], out.estimates["dead reckoning"])
    assert out.unmodelled.size == 3 - out.dropped["direct"]  # every ok fix, here all fed
    # without eq. 1's tracker (its extraction not run) the same draws give the same direct track
    alone = direct_drive(route, np.random.default_rng(4), design, None, table, speed_sigma=0.1,
                         n_epochs=3)  # fmt: skip
    assert set(alone.estimates) == set(TRACKERS) - {"eq. 1"} and set(alone.seconds) == {"direct"}
    for name in alone.estimates:
        np.testing.assert_array_equal(alone.estimates[name], out.estimates[name])
    # a replay of its fixes told the same table repeats the drive to the last digit, with no
    # fit; told another table it moves the direct track only (dead reckoning is the messages')
    # every ok fix is fed (no max_unmodelled), every other epoch dropped
    assert len(alone.fixes) == 3
    assert sum(f is not None and f.ok for f in alone.fixes) == 3 - alone.dropped["direct"]
    monkeypatch.setattr(dt, "direct_fix", None)  # a replay must not fit
    same = direct_drive(route, np.random.default_rng(4), design, None, table, speed_sigma=0.1,
                        n_epochs=3, replay=alone)  # fmt: skip
    for name in alone.estimates:
        np.testing.assert_array_equal(same.estimates[name], alone.estimates[name])
    np.testing.assert_array_equal(same.los_errors["direct"], alone.los_errors["direct"])
    assert same.fixes == alone.fixes and same.dropped == alone.dropped
    np.testing.assert_array_equal(same.unmodelled, alone.unmodelled)
    np.testing.assert_array_equal(same.speed_errors, alone.speed_errors)
    loose = ElevationSigmas(np.zeros(1), np.radians([5.0]), np.radians([5.0]))
    other = direct_drive(route, np.random.default_rng(4), design, None, loose, speed_sigma=0.1,
                         n_epochs=3, replay=alone)  # fmt: skip
    for name in ("dead reckoning", "direct speed alone"):
        np.testing.assert_array_equal(other.estimates[name], alone.estimates[name])
    assert not np.array_equal(other.estimates["direct"], alone.estimates["direct"])
    # a replay with the second start asked for runs no eq. 1 either (the fixes are given)
    monkeypatch.setattr(dt, "_eq1_los", None)
    direct_drive(route, np.random.default_rng(4), design, None, table, speed_sigma=0.1,
                 n_epochs=3, replay=alone, second_start=True)  # fmt: skip
    # another generator's, start's or array's drive of the same route is refused, not replayed
    for rng_, kw in ((np.random.default_rng(5), {}),
                     (np.random.default_rng(4), {"start": traj.position[0] + 0.05})):  # fmt: skip
        with pytest.raises(ValueError, match=r"^replay: not a drive of this route, generator"):
            direct_drive(route, rng_, design, None, table, speed_sigma=0.1, n_epochs=3,
                         replay=alone, **kw)  # fmt: skip
    old = dataclasses.replace(alone, fixes=())  # pickled before the fixes were kept
    with pytest.raises(ValueError, match=r"^replay: holds no fixes"):
        direct_drive(route, np.random.default_rng(4), design, None, table, n_epochs=3,
                     replay=old)  # fmt: skip
    with pytest.raises(TypeError, match=r"^fixes"):
        dataclasses.replace(alone, fixes=(alone.fixes[0], "fix", None))
    with pytest.raises(ValueError, match=r"^fixes: expected one per epoch"):
        dataclasses.replace(alone, fixes=alone.fixes[:2])
    with pytest.raises(ValueError, match=r"^replay, eq1_table"):
        direct_drive(route, np.random.default_rng(4), design, table, table, replay=alone)
    with pytest.raises(ValueError, match=r"^replay: not a drive of this route"):
        direct_drive(route, np.random.default_rng(4), design, None, table, n_epochs=4,
                     replay=alone)  # fmt: skip
    with pytest.raises(TypeError, match=r"^replay"):
        direct_drive(route, np.random.default_rng(4), design, None, table, replay=alone.fixes)
    monkeypatch.undo()
    monkeypatch.setattr(dt, "direct_fix", recording)
    with pytest.raises(TypeError, match=r"^eq1_table"):
        direct_drive(route, np.random.default_rng(4), design, "0.2/0.1", table, n_epochs=1)
    # the same drive with every fix past a tiny unmodelled share dropped: the direct tracker is
    # dead reckoning on the same messages
    strict = direct_drive(route, np.random.default_rng(4), design, table, table, n_epochs=3,
                          max_unmodelled=1e-12)  # fmt: skip
    assert strict.dropped["direct"] == 3 and strict.unmodelled.size >= 1
    np.testing.assert_allclose(strict.estimates["direct"], strict.estimates["dead reckoning"],
                               atol=1e-12)  # fmt: skip
    # the height told known: the fixes move the direct track's position, not its height
    known = direct_drive(route, np.random.default_rng(4), design, table, table, n_epochs=3,
                         start_height_sigma=1e-6)  # fmt: skip
    z0 = traj.position[0, 2]
    assert np.abs(known.estimates["direct"][:, 2] - z0).max() < 1e-4
    assert np.abs(out.estimates["direct"][:, 2] - z0).max() > 1e-3  # told 10 cm, it moves
    for bad in (0.0, -0.1, 25.0):
        with pytest.raises(ValueError, match=r"^start_height_sigma"):
            direct_drive(route, np.random.default_rng(4), design, table, table,
                         start_height_sigma=bad)  # fmt: skip
    with pytest.raises(ValueError, match=r"^max_unmodelled"):
        direct_drive(route, np.random.default_rng(4), design, table, table, max_unmodelled=2.0)
    with pytest.raises(ValueError, match=r"^speed_sigma"):
        direct_drive(route, np.random.default_rng(4), design, table, table, speed_sigma=-1.0)
    with pytest.raises(ValueError, match=r"^diffuse_above.*without"):  # refused, not a failed fit
        direct_drive(route, np.random.default_rng(4), design, table, table, diffuse_above=0.1)
    with pytest.raises(TypeError, match=r"^route"):
        direct_drive("italiano2026-straight", np.random.default_rng(4), design, table, table)
    # an entry fix given (the design's drawn start): every tracker starts there, the draws the
    # same; dead reckoning is JAVELIN's own run from it
    p0 = traj.position[0] + np.array([0.7, -0.4, 0.03])
    moved = direct_drive(route, np.random.default_rng(4), design, None, table, n_epochs=3,
                         start_sigma=1.0, start_height_sigma=0.05, start=p0)  # fmt: skip
    d1 = design.with_(base_station=tuple(float(v) for v in route.arrays[0].origin),
                      sigma_p0_ue=1.0, sigma_p0_height=0.05)  # fmt: skip
    run = run_javelin([None] * 3, speed, heading, float(traj.t[1] - traj.t[0]), p0, d1)
    np.testing.assert_allclose(moved.estimates["dead reckoning"], run.estimates, atol=1e-12)
    assert not np.allclose(moved.estimates["direct"], moved.estimates["dead reckoning"])
    # the second start: the fit also started from eq. 1's line of sight at the predicted range
    # (0.8 m off the prediction here on the first epoch); the same draws, the same dead reckoning
    starts.clear()
    two = direct_drive(route, np.random.default_rng(4), design, None, table, n_epochs=3,
                       start_sigma=1.0, start_height_sigma=0.05, start=p0,
                       second_start=True)  # fmt: skip
    assert len(starts) > 3 and np.hypot(*(starts[1] - p0)[:2]) > 0.25  # epoch 0 started twice
    np.testing.assert_array_equal(
        two.estimates["dead reckoning"], moved.estimates["dead reckoning"]
    )
    assert set(two.seconds) == {"direct"} and np.all(two.seconds["direct"] > 0)
    with pytest.raises(TypeError, match=r"^second_start"):
        direct_drive(route, np.random.default_rng(4), design, None, table, second_start="yes")
    with pytest.raises(ValueError, match=r"^start: .*of its told sigmas"):  # 0.6 m, told 5 cm
        direct_drive(route, np.random.default_rng(4), design, None, table, n_epochs=1,
                     start_sigma=0.05, start=p0)  # fmt: skip
    with pytest.raises(ValueError, match=r"^start"):
        direct_drive(route, np.random.default_rng(4), design, None, table, n_epochs=1,
                     start=p0[:2])  # fmt: skip


def test_step_sigma_is_what_the_tracker_is_told(route):
    """The study's JAVELIN told a step's speed sigma predicts as a design told it would."""
    from tunnelkit.design.traceddirect import _StepSigma
    from tunnelkit.reproduce.javelin_traced import los_design
    from tunnelkit.tracking.javelin import Javelin

    d = los_design()
    p0 = route.trajectory.position[0]
    told = _StepSigma(p0, d)
    told.step_sigma = 0.05
    design = Javelin(p0, d.with_(sigma_speed=0.05))
    plain = _StepSigma(p0, d)
    for jav in (told, design, plain):
        jav.predict(10.0, 0.1, 0.1)
    np.testing.assert_allclose(told.P, design.P, rtol=1e-12)
    assert not np.allclose(plain.P, told.P)


@pytest.mark.parametrize("k", [0, 8, 24])
def test_second_order_masks_are_the_image_method_at_each_element(route, k):
    """Each element's mask of the second-order paths is what the image method finds with that
    element as the reference antenna (brute force, every fifth element); the reference element's
    paths are among them, and the masks leave out paths part of the array misses."""
    arr, ue, vel = route.paths(k)[0], route.trajectory.position[k], route.trajectory.velocity[k]
    fc = route.config.fc
    paths, masks = visible_second_order(route.tunnel, arr, ue, vel, fc, 64, min_share=0.01)
    names = [p.surface for p in paths]
    assert len(set(names)) == len(names) and masks.shape == (arr.M, len(paths))
    for m in range(0, arr.M, 5):
        local = np.roll(arr.local - arr.local[m], -m, axis=0)
        one = ArrayGeometry(local, arr.world[m], arr.azimuth, arr.elevation)
        seen = {p.surface for p in trace_paths(route.tunnel, one, ue, vel, fc=fc, kinds=route.kinds,
                                               order=2) if p.kind == SECOND_ORDER}  # fmt: skip
        assert seen == {n for n, b in zip(names, masks[m], strict=True) if b}, (m, seen)
    ref = {p.surface for p in trace_paths(route.tunnel, arr, ue, vel, fc=fc, kinds=route.kinds,
                                          order=2) if p.kind == SECOND_ORDER}  # fmt: skip
    assert ref == {n for n, b in zip(names, masks[0], strict=True) if b}
    # the model keeps the n strongest that a quarter of the elements see, with their masks
    p2, m2, _ = predicted_model(route, arr, ue, vel, 3, element_second_order=True)
    assert m2.shape == (arr.M, len(p2)) and np.all(m2[:, -3:].mean(axis=0) >= 0.25)
    assert [p.kind for p in p2[-3:]] == [SECOND_ORDER] * 3


def test_the_direct_column_reads_the_shipped_table_and_refuses_other_scenes():
    """The tables' direct column: each paper scene's told table is the shipped survey's (its
    command in the record); a scene without one has no column; bad names are refused by name."""
    import json

    from tunnelkit.design.directsurvey import SURVEY_SCALE
    from tunnelkit.reproduce import javelin_direct as jd
    from tunnelkit.reproduce.javelin_tables import _traced_routes
    from tunnelkit.scenarios import data_dir

    for sc in ("italiano2026-straight", "italiano2026-slalom"):
        rec = json.loads((data_dir() / "rt" / "direct" / f"{sc}.json").read_text())
        assert rec["scenario"] == sc and rec["command"].startswith("python benchmarks/")
        t = jd.direct_table(sc)
        np.testing.assert_allclose(np.degrees(t.sigma_azimuth),
                                   np.asarray(rec["table_deg"]["sigma_azimuth"]) * SURVEY_SCALE)  # fmt: skip
        assert "seed 0" in jd.direct_note(sc)
    assert jd.direct_table("jiang2023-straight") is None
    with pytest.raises(ValueError, match=r"^scenario.*ships no"):
        jd.direct_scores("jiang2023-straight", 1, np.random.default_rng(0))
    with pytest.raises(ValueError, match=r"^scenario.*ships no"):
        jd.direct_note("jiang2023-straight")
    for bad in ("a\0b", ""):
        with pytest.raises(ValueError, match=r"^scenario"):
            jd.direct_table(bad)
    for path in ("../rt/direct/italiano2026-straight", "data/scenarios/italiano2026-straight.toml"):
        assert jd.direct_table(path) is None  # a scenario file ships no table
    with pytest.raises(TypeError, match=r"^scenario"):
        jd.direct_table(["italiano2026-straight"])
    with pytest.raises(ValueError, match=r"^n_epochs"):
        jd.direct_scores("italiano2026-straight", 0, np.random.default_rng(0))
    with pytest.raises(TypeError, match=r"^rng"):
        jd.direct_scores("italiano2026-straight", 1, 7)
    assert _traced_routes(("paper", "ml"), "sionna", True)[-1] == jd.DIRECT_COLUMN[1]
    assert jd.DIRECT_COLUMN[1] not in _traced_routes(("paper", "ml"), "sionna")
    assert _traced_routes(("paper", "ml"), "image", True) == ("paper", "ml")


def test_repointed_keeps_the_range_and_height_and_takes_the_measured_direction():
    """The second start: a prediction at the true point's range and height but another bearing
    is moved onto the true point; any prediction lands on the measured azimuth at its own range
    and height."""
    from tunnelkit.design.traceddirect import repointed
    from tunnelkit.geometry import spherical
    from tunnelkit.tracking.measurements import PathMeasurements

    o = np.array([0.0, -0.5, 4.8])
    p = np.array([23.0, -2.5, 1.5])
    phi, psi, r = spherical(p - o)
    los = PathMeasurements.from_arrays([phi], [psi], [r], [r], [0.0], warn=False)
    rh, dz = np.hypot(*(p - o)[:2]), p[2] - o[2]
    a = phi + np.radians(3.0)
    pred = o + np.array([rh * np.cos(a), rh * np.sin(a), dz])
    np.testing.assert_allclose(repointed(los, o, pred), p, atol=1e-9)
    far = np.array([30.0, -1.0, 1.6])
    q = repointed(los, o, far)
    assert q[2] == far[2]
    np.testing.assert_allclose(np.arctan2(q[1] - o[1], q[0] - o[0]), phi, atol=1e-12)
    with pytest.raises(ValueError, match=r"^prediction: at the origin"):
        repointed(los, o, o)
    with pytest.raises(ValueError, match=r"^los: expected one path"):
        repointed(los.subset(np.array([], int)), o, far)
    with pytest.raises(TypeError, match=r"^los"):
        repointed((phi, psi), o, far)


def test_every_shipped_design_survey_is_what_its_command_writes():
    """Each design survey shipped (data/rt/direct/<scenario>-<array>.json) loads checked, and the
    command it records surveys that route: its scene, array, seed, drive count and bin count,
    told the constant DESIGN_SIGMAS_DEG, with one finite positive sigma per bin."""
    import itertools
    import re
    import shlex

    from tunnelkit.design import directsurvey as ds
    from tunnelkit.design.los import ElevationSigmas
    from tunnelkit.scenarios import data_dir

    routes = [
        re.fullmatch(r"(.+)-(\d+x\d+)", p.stem)
        for p in (data_dir() / "rt" / "direct").glob("*.json")
    ]
    routes = sorted(m.groups() for m in routes if m)  # the tables' surveys (<scenario>.json) apart
    assert len(routes) >= 2
    for scenario, array in routes:
        p = ds.survey_path(scenario, array)
        rec = ds.survey_record(scenario, array)
        argv = shlex.split(rec["command"])
        assert argv[:2] == ["python", "benchmarks/bench_rt_direct.py"], p.name
        flags = dict(itertools.pairwise(argv))
        assert flags.get("--scenario", "italiano2026-straight") == scenario, p.name
        assert flags["--design-array"] == array and flags["--sigmas"] == "2/1", p.name
        assert int(flags["--seed"]) == rec["seed"] and int(flags["--runs"]) == rec["runs"], p.name
        assert str(rec["bins"]) in argv[argv.index("--bins") + 1 :], p.name
        told = ElevationSigmas.from_dict(rec["told_deg"])
        assert np.degrees([told.sigma_azimuth[0], told.sigma_elevation[0]]).tolist() == (
            pytest.approx(list(ds.DESIGN_SIGMAS_DEG))
        ), p.name
        t = rec["table_deg"]
        assert len(t["elevation"]) == rec["bins"] and np.all(np.diff(t["elevation"]) > 0), p.name
        for key in ("sigma_azimuth", "sigma_elevation"):
            v = np.asarray(t[key])
            assert v.shape == (rec["bins"],) and np.all(np.isfinite(v) & (v > 0)), p.name


def test_survey_records_are_checked_and_a_design_route_without_one_is_told_the_constant(
    tmp_path, monkeypatch
):
    """directsurvey: a design route's record (<scenario>-<array>.json) is its survey's RMS times
    SURVEY_SCALE; a route without one is told DESIGN_SIGMAS_DEG and its summary says so; a
    record of another route, or without a table, is refused naming the scenario."""
    import json

    import tunnelkit.scenarios as scenarios
    from tunnelkit.design import directsurvey as ds
    from tunnelkit.design.los import ElevationSigmas

    (tmp_path / "rt" / "direct").mkdir(parents=True)
    monkeypatch.setattr(scenarios, "data_dir", lambda: tmp_path)
    ds._load.cache_clear()
    monkeypatch.setattr(ds, "_load", ds._load.__wrapped__)  # no cache across the test's records
    table = {
        "elevation": [-20.0, -5.0],
        "sigma_azimuth": [0.05, 0.3],
        "sigma_elevation": [0.04, 0.1],
    }
    rec = {"scenario": "sc", "array": "8x8", "source": "s", "command": "python x", "seed": 0,
           "runs": 4, "bins": 2, "told_deg": table, "table_deg": table}  # fmt: skip
    (tmp_path / "rt" / "direct" / "sc-8x8.json").write_text(json.dumps(rec))
    t = ds.design_table("sc", "8x8")
    want = ElevationSigmas.from_dict(table)
    psi = np.radians([-30.0, -12.0, 0.0])
    for got, ref in zip(t.at(psi), want.at(psi), strict=True):
        np.testing.assert_allclose(got, ds.SURVEY_SCALE * ref)
    s = ds.direct_summary("sc", "8x8", {"a": 1})
    assert s["survey"]["command"] == "python x" and s["survey"]["scale"] == ds.SURVEY_SCALE
    assert s["told_deg"] == t.as_dict() and s["options"] == {"a": 1}
    # another array of the same scene ships nothing: the constant, and the summary says so
    c = ds.design_table("sc", "4x4")
    assert np.degrees([c.sigma_azimuth[0], c.sigma_elevation[0]]).tolist() == pytest.approx(
        list(ds.DESIGN_SIGMAS_DEG)
    )
    assert ds.direct_summary("sc", "4x4", {})["survey"] is None
    assert ds.survey_record("sc") is None  # the tables' route of the scene: none
    # a record naming another route, or without a table, is refused
    (tmp_path / "rt" / "direct" / "sc-4x4.json").write_text(json.dumps(rec))
    with pytest.raises(ValueError, match=r"^scenario:.*array '8x8'"):
        ds.design_table("sc", "4x4")
    (tmp_path / "rt" / "direct" / "sc.json").write_text(json.dumps({"scenario": "sc"}))
    with pytest.raises(ValueError, match=r"^scenario:.*missing"):
        ds.survey_record("sc")
    with pytest.raises(ValueError, match=r"^array"):
        ds.design_table("sc", "8by8")
    with pytest.raises(TypeError, match=r"^record"):
        ds.surveyed_table({"table": table})
    for bad in (0, -1, np.nan):
        with pytest.raises(ValueError, match=r"^factor"):
            want.scaled(bad)
