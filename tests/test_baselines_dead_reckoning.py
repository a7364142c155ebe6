"""The baselines beside Jiang's and Halili's trackers: the filters' own motion model from the same
prior (or GNSS fix) with every measurement dropped, checked against the closed form."""

from __future__ import annotations

import numpy as np

from tunnelkit import doppler_drive as dv
from tunnelkit.reproduce import run
from tunnelkit.reproduce.jiang_tables import PREDICTION_ONLY, table_rows
from tunnelkit.tracking import doppler as dp
from tunnelkit.tracking import registry
from tunnelkit.tracking import virtual_station as vs


def test_halili_dead_reckoning_is_the_fix_carried_on_at_its_velocity():
    drive = dv.make_drive(duration=8.0, pass_time=4.0)
    fix = dv.gnss_fix(drive, np.random.default_rng(3))
    pos = dp.dead_reckoning(drive, fix)
    t = drive.t - drive.t[0]
    np.testing.assert_allclose(pos, fix.position + t[:, None] * fix.velocity, atol=1e-9)
    errs = dp.error_study(drive, np.random.default_rng(4), sigmas={"32.79 Hz": 32.79})
    assert set(errs) == {(a, "32.79 Hz") for a in dp.APPROACHES} | {(dp.DEAD_RECKONING, "-")}
    rep = run("halili", runs=2, seed=0)
    last = rep.rows[-1]
    assert last[0] == dp.DEAD_RECKONING and last[-1] is None and last[7] > 0


def test_jiang_prediction_only_is_the_cv_model_from_the_prior():
    exp = vs.experiment("jiang2023-straight", level=0)
    Z, x0 = exp.simulate(2, np.random.default_rng(1))
    est = registry.get("jiang2023", "EKF").run(exp.model, np.full_like(Z, np.nan), x0, exp.P0)
    t = np.arange(Z.shape[1]) * exp.model.period
    expect = x0[:, None, :2] + t[None, :, None] * x0[:, None, 2:]
    np.testing.assert_allclose(est[..., :2], expect, atol=1e-9)
    rows = table_rows("jiang2023_table2", los=False, runs=2, seed=0, levels=[0])
    base = {r["algorithm"]: r for r in rows}
    assert base[PREDICTION_ONLY]["paper_mean_m"] is None
    # the radio pays: every filter well ahead of the baseline on the same runs
    for name in ("EKF", "UKF", "UPF"):
        assert base[name]["ours_rmse_m"] < 0.5 * base[PREDICTION_ONLY]["ours_rmse_m"]
    # the table's bound is the drive's own (no process noise): every row lies above it
    assert all(r["rmse_over_pcrlb"] > 1.0 for r in rows), rows
