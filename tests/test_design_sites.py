"""A row of sites along a long tunnel (tunnelkit.design.sites) and the study on it
(tunnelkit.design.longtunnel)."""

from __future__ import annotations

from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from tunnelkit.design import DesignSetup
from tunnelkit.design.achievable import path_error_model
from tunnelkit.design.errordraws import draw_calibration
from tunnelkit.design.fastroute import bound_drive
from tunnelkit.design.setup import Mount
from tunnelkit.design.sites import SiteRow, site_drive, site_route
from tunnelkit.scenarios import Trajectory


@cache
def _setup(name: str = "example-rectangular-28ghz") -> DesignSetup:
    return DesignSetup.from_scenario(name)


@cache
def _row(spacing: float = 100.0, length: float = 400.0, max_range=None) -> SiteRow:
    return SiteRow.along(_setup(), spacing, length, max_range=max_range)


def test_one_site_row_draws_what_bound_drive_draws():
    setup = _setup("italiano2026-straight")
    row = SiteRow(setup, 100.0)  # the next site would stand outside the 100 m tunnel
    assert row.count == 1
    route = site_route(row, "8x8")
    assert np.array_equal(route.rows, np.arange(len(setup.trajectory)))
    a = site_drive(row, route, np.random.default_rng(5))
    b = bound_drive(path_error_model(setup, "8x8"), setup, "8x8", np.random.default_rng(5))
    for x, y in zip(a.epochs, b.epochs, strict=True):
        for f in ("phi", "psi", "kappa", "d", "v", "cov", "sigma_d"):
            assert np.array_equal(getattr(x, f), getattr(y, f), equal_nan=True), f
        assert y.site is None and np.array_equal(x.site, b.base_station)
    assert np.array_equal(a.speed, b.speed) and np.array_equal(a.heading, b.heading)


def test_rows_repeat_every_spacing_and_match_a_model_of_the_moved_site():
    row = _row()
    traj = row.setup.trajectory
    step = float(np.linalg.norm(traj.velocity[0]) * traj.period)
    route = site_route(row, "4x4")
    n_rows = route.route.model.exists.shape[0]
    # 100 m at 80 km/h and 0.1 s is 45 steps: one spacing's positions, plus the stretches
    # before the first and after the last site
    assert row.count == 4 and np.isclose(100.0 / step, 45.0)
    assert n_rows < 45 + 2 * (0.5 * 100.0 + 25.0) / step + 2
    assert n_rows < len(traj) / 2
    k = int(np.flatnonzero(route.site == 2)[10])
    same = np.flatnonzero(route.rows == route.rows[k])
    assert set(route.site[same]) >= {1, 2}  # the same row serves the same offset at two sites
    # the row of epoch k against the model of the site moved to site 2, at that epoch alone
    shift = np.array([2 * row.spacing, 0.0, 0.0])
    mounts = tuple(
        Mount(m.name, m.centre + shift, m.azimuth, m.elevation) for m in row.setup.mounts
    )
    one = Trajectory(t=traj.t[k : k + 1], position=traj.position[k : k + 1],
                     velocity=traj.velocity[k : k + 1])  # fmt: skip
    direct = path_error_model(replace(row.setup, mounts=mounts, trajectory=one), "4x4")
    m, r = route.route.model, route.rows[k]
    assert np.array_equal(direct.exists[0], m.exists[r])
    ex = m.exists[r]
    assert np.allclose(direct.truth[0][ex], m.truth[r][ex], rtol=1e-9, atol=1e-9)
    assert np.allclose(direct.crlb[0], m.crlb[r], rtol=1e-6, atol=1e-15)
    a0 = row.setup.arrays("4x4")
    assert any(np.allclose(route.origin[k], a.origin + shift) for a in a0)


def test_the_drive_carries_each_epochs_serving_site():
    row = _row()
    route = site_route(row, "4x4")
    drive = site_drive(row, route, np.random.default_rng(0))
    sites = [e.site for e in drive.epochs]
    assert np.allclose(np.array(sites), route.origin)
    assert len({round(float(s[0])) for s in sites}) >= row.count


def test_no_site_in_range_leaves_the_epoch_without_measurement():
    row = _row(max_range=30.0)
    route = site_route(row, "4x4")
    drive = site_drive(row, route, np.random.default_rng(0))
    gone = np.array([e is None for e in drive.epochs])
    assert np.array_equal(gone, ~route.served)
    _, dist, _ = row.serving(row.setup.trajectory.position)
    assert np.array_equal(gone, dist > 30.0) and 0 < gone.sum() < gone.size


def test_the_tracker_needs_the_serving_site():
    from tunnelkit.design.arrayjob import design_planes, javelin_config, median_sigmas
    from tunnelkit.simulation import evaluate

    row = _row(length=250.0)
    route = site_route(row, "4x4")
    drive = site_drive(row, route, np.random.default_rng(1))
    design = javelin_config(
        median_sigmas(route.route.model), route.route.min_d, design_planes(row.setup)
    )
    err = np.linalg.norm(evaluate(drive, design).estimates[:, :2] - drive.truth[:, :2], axis=1)
    for e in drive.epochs:
        e.site = None  # every epoch measured from the drive's last site instead
    wrong = evaluate(drive, design).estimates
    err_wrong = np.linalg.norm(wrong[:, :2] - drive.truth[:, :2], axis=1)
    assert np.quantile(err, 0.9) < 0.2
    assert np.quantile(err_wrong, 0.9) > 5 * np.quantile(err, 0.9)


@pytest.mark.parametrize(
    ("kw", "match"),
    [
        ({"spacing": 0.0}, "spacing"),
        ({"spacing": -5.0}, "spacing"),
        ({"spacing": 1e4}, "spacing: .* longer than the tunnel"),
        ({"spacing": 0.01}, "spacing: .* overlap"),
        ({"spacing": 100.0, "count": 9}, "count"),
        ({"spacing": 100.0, "max_range": 0.0}, "max_range"),
    ],
)
def test_row_refusals_name_the_parameter(kw, match):
    setup = _row().setup
    with pytest.raises(ValueError, match=match):
        SiteRow(setup, **kw)


def test_row_refuses_local_features_and_sites_outside():
    setup = _setup("italiano2026-straight")
    with pytest.raises(ValueError, match=r"setup: .*plates"):
        SiteRow(setup, 40.0)  # two sites over a tunnel with RRM plates
    with pytest.raises(ValueError, match="first"):
        SiteRow.along(_setup(), 100.0, 400.0, first=1e3)
    with pytest.raises(ValueError, match=r"spacing: .* 16x16 arrays .* overlap"):
        site_route(SiteRow(_row().setup, 0.03, count=3), "16x16")


def test_long_tunnel_study_rows():
    from tunnelkit.design.longtunnel import long_tunnel_study

    res = long_tunnel_study(_setup(), ("4x4",), (100.0,), length=250.0, runs=2, target=0.5)
    (r,) = res.rows
    assert r["array"] == "4x4" and r["spacing"] == 100.0 and r["sites"] == _row(length=250.0).count
    assert r["p90"] > 0 and r["worst_p90"] > 0 and r["rmse"] > 0
    assert abs(r["worst_offset"]) <= 50.0 + 10.0  # within half a spacing of its site
    assert np.isclose(r["gain"], r["dr_p90"] / r["p90"])
    assert r["meets"] == (r["p90"] <= 0.5) and res.meeting() == (
        [("4x4", 100.0)] if r["meets"] else []
    )
    assert "| 4x4 | 100 |" in res.table()
    # the yield: the share of the two runs whose own p90 meets the target, in its interval
    assert r["yield"] in (0.0, 0.5, 1.0) and r["yield_ci"][0] <= r["yield"] <= r["yield_ci"][1]
    kw = {"length": 250.0, "runs": 2}
    easy = long_tunnel_study(_setup(), ("4x4",), (100.0,), target=1e3, **kw).rows[0]
    hard = long_tunnel_study(_setup(), ("4x4",), (100.0,), target=1e-6, **kw).rows[0]
    assert easy["yield"] == 1.0 and hard["yield"] == 0.0 and easy["p90"] == r["p90"]


def test_each_site_is_a_unit_of_its_own():
    from tunnelkit.design import DesignImpairments

    imp = DesignImpairments(phase_error_deg=1.5, gain_error_db=0.25)
    # one site: the unit drawn first, as bound_drive draws it
    setup = _setup("italiano2026-straight")
    row1 = SiteRow(setup, 100.0)
    a = site_drive(row1, site_route(row1, "4x4", imp), np.random.default_rng(2))
    m = path_error_model(setup, "4x4", imp)
    b = bound_drive(m, setup, "4x4", np.random.default_rng(2))
    assert all(np.array_equal(x.phi, y.phi) for x, y in zip(a.epochs, b.epochs, strict=True))
    # a row: each site's own draw moves only the epochs that site serves
    row = _row()
    route = site_route(row, "4x4", imp)
    model = route.route.model
    units = [draw_calibration(model, np.random.default_rng(10 + i)) for i in range(row.count)]
    same = [units[0]] * row.count
    d1 = site_drive(row, route, np.random.default_rng(3), calibration=units)
    d0 = site_drive(row, route, np.random.default_rng(3), calibration=same)
    moved = np.array([not np.array_equal(x.phi, y.phi) for x, y in zip(d1.epochs, d0.epochs)])
    assert not moved[route.site == 0].any() and moved[route.site != 0].all()
    short = site_drive(row, route, np.random.default_rng(3), calibration=units, n_epochs=7)
    assert len(short.epochs) == 7
    assert all(np.array_equal(x.phi, y.phi) for x, y in zip(short.epochs, d1.epochs[:7]))
    with pytest.raises(TypeError, match="calibration"):
        site_drive(row, route, np.random.default_rng(3), calibration=units[:1])


def test_long_tunnel_command(capsys):
    import json

    from tunnelkit.cli import main

    args = ["long-tunnel", "example-rectangular-28ghz", "--arrays", "4x4", "8x8"]
    args += ["--spacings", "100", "--length", "250", "--runs", "1", "--format", "json"]
    assert main(args) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["impairments"] == "calibrated" and [r["array"] for r in out["rows"]] == [
        "4x4",
        "8x8",
    ]
    # every array and spacing on the same random numbers: dead reckoning the same in every row
    assert out["rows"][0]["dr_p90"] == out["rows"][1]["dr_p90"]


def test_the_messages_follow_the_odometry_model():
    from tunnelkit.design.longtunnel import long_tunnel_study
    from tunnelkit.odometry import AUTOMOTIVE, WHITE

    row = _row(length=250.0)
    route = site_route(row, "4x4")
    plain = site_drive(row, route, np.random.default_rng(3))
    white = site_drive(row, route, np.random.default_rng(3), odometry=WHITE)
    assert np.array_equal(plain.speed, white.speed) and np.array_equal(plain.heading, white.heading)
    car = site_drive(row, route, np.random.default_rng(3), odometry=AUTOMOTIVE)
    assert np.isnan(car.speed).any() and not np.isnan(white.speed).any()  # 10 % of them lost
    with pytest.raises(TypeError, match="odometry"):
        site_drive(row, route, np.random.default_rng(3), odometry="automotive")
    kw = {"length": 400.0, "runs": 2, "seed": 1}
    res = {
        o: long_tunnel_study(_setup(), ("8x8",), (200.0,), odometry=o, **kw).rows[0]
        for o in ("white", "automotive")
    }
    # over 400 m a car's odometry drifts several times further than the paper's white messages
    assert res["automotive"]["dr_p90"] > 2 * res["white"]["dr_p90"], res
    with pytest.raises(ValueError, match="odometry"):
        long_tunnel_study(_setup(), ("8x8",), (200.0,), odometry="gyro", **kw)


def test_a_ue_half_a_spacing_before_a_site_maps_inside_the_first_sites_frame():
    """At 70 km/h on the Mont Blanc preset a UE lies exactly half a spacing before a site; seen
    from the first site that is the row's -x end. The first site's frame has room beyond it."""
    setup = _setup("mont-blanc-28ghz")
    row = SiteRow.along(setup, 100.0, 2000.0, speed=70.0 / 3.6)
    route = site_route(row, "4x4")
    assert route.rows.size == len(row.setup.trajectory) and route.served.all()
    inner = (row.centres[0] < row.setup.trajectory.position[:, 0]) & (
        row.setup.trajectory.position[:, 0] < row.centres[-1]
    )
    assert np.all(np.abs(route.offset[inner]) <= 50.0 + 1e-9)  # between sites: the nearest


def test_the_row_bound_and_the_tracker_told_the_odometry():
    """Along a row of sites on a car's odometry: the posterior CRLB of the drive
    (:func:`~tunnelkit.design.sites.row_pcrlb`) lies below dead reckoning's bound (the sites'
    information) and reduces to it with no site in range; JAVELIN told the model and not told it
    both stay above it (Monte-Carlo noise allowed), the told one no worse than the untold."""
    from tunnelkit.design.longtunnel import long_tunnel_study
    from tunnelkit.design.sites import row_pcrlb
    from tunnelkit.odometry import AUTOMOTIVE
    from tunnelkit.reckoning import dead_reckoning_bound

    row = _row(200.0, 600.0)
    route = site_route(row, "8x8")
    traj = row.setup.trajectory
    v = np.linalg.norm(traj.velocity[:, :2], axis=1)
    th = np.arctan2(traj.velocity[:, 1], traj.velocity[:, 0])
    dr = dead_reckoning_bound(traj.t, v, th, AUTOMOTIVE, sigma_start=1.0)
    bound = row_pcrlb(row, route, AUTOMOTIVE, 1.0)
    assert np.all(bound <= dr * (1 + 1e-9)) and bound[-1] < 0.2 * dr[-1]
    off = replace(route, served=np.zeros_like(route.served))
    np.testing.assert_allclose(row_pcrlb(row, off, AUTOMOTIVE, 1.0), dr, rtol=1e-12)
    with pytest.raises(ValueError, match="geometry"):
        row_pcrlb(row, replace(route, geometry=None), AUTOMOTIVE)
    kw = {"length": 600.0, "runs": 3, "seed": 4, "odometry": "automotive"}
    told, untold = (
        long_tunnel_study(_setup(), ("8x8",), (200.0,), told_odometry=t, **kw)
        for t in (True, False)
    )
    a, b = told.rows[0], untold.rows[0]
    assert told.told_odometry and not untold.told_odometry and a["bound"] == b["bound"]
    assert a["rmse"] >= 0.7 * a["bound"] and b["rmse"] >= 0.7 * b["bound"]
    assert a["rmse"] <= b["rmse"] and a["dr_rmse"] == b["dr_rmse"]
    assert "| 8x8 | 200 | 3 |" in told.table() and told.to_json()["told_odometry"]


def test_the_tracker_told_a_model_of_its_own():
    """``told_odometry`` an Odometry: JAVELIN is told that model instead of the messages' (the
    messages, dead reckoning and the bound unchanged); told the messages' own model it is
    ``told_odometry=True``, told one with a heading bias at the start 100 times smaller another
    tracker."""
    from tunnelkit.design.longtunnel import long_tunnel_study
    from tunnelkit.odometry import AUTOMOTIVE

    kw = {"length": 600.0, "runs": 2, "seed": 4, "odometry": "automotive"}
    runs = {
        k: long_tunnel_study(_setup(), ("8x8",), (200.0,), told_odometry=t, **kw).rows[0]
        for k, t in (
            ("true", True),
            ("same", AUTOMOTIVE),
            ("no b0", replace(AUTOMOTIVE, heading_bias=AUTOMOTIVE.heading_bias / 100)),
        )
    }
    assert runs["same"] == runs["true"]
    other = runs["no b0"]
    assert other["rmse"] != runs["true"]["rmse"]
    assert other["bound"] == runs["true"]["bound"] and other["dr_rmse"] == runs["true"]["dr_rmse"]
    with pytest.raises(TypeError):
        long_tunnel_study(_setup(), ("8x8",), (200.0,), told_odometry="automotive", **kw)
