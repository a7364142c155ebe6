"""Notebook 05: the unscented particle filter, vectorised over particles vs one filterpy UKF each.

Both run the same algorithm (UKF proposal per particle, eq. 46-58; sampling, weights, systematic
resampling, eq. 59-63) on one 100-epoch run of the straight NLOS scenario at (2 deg, 2 m) with
500 particles. The baseline builds one filterpy ``UnscentedKalmanFilter`` per particle per epoch
(`tunnelkit.tracking.upf.ukf_proposal_reference`); everything else is shared.
"""

from __future__ import annotations

import warnings

import numpy as np
from run import Case

from tunnelkit.tracking import upf
from tunnelkit.tracking import virtual_station as vs

N_PARTICLES = 500
STEPS = 100


def _run_vectorised(exp, Z, x0, proposal):
    f = upf.UnscentedParticleFilter(
        exp.model,
        x0,
        exp.P0,
        rng=np.random.default_rng(1),
        n_particles=N_PARTICLES,
        proposal=proposal,
    )
    for k in range(STEPS):
        f.step(Z[k], first=(k == 0))
    return f.x


def _run_loop(exp, Z, x0):
    """UPF with the proposal of every particle from its own filterpy UKF (predict + update)."""
    m = exp.model
    rng = np.random.default_rng(1)
    f = upf.UnscentedParticleFilter(
        m, x0, exp.P0, rng=rng, n_particles=N_PARTICLES, proposal="carried"
    )
    f.update(Z[0])
    LQ = np.linalg.cholesky(m.Q)
    for k in range(1, STEPS):
        parts, covs = f.particles[0], f.covs[0]
        m_post, P_post = upf.ukf_proposal_reference(m, parts, covs, Z[k])
        Lq = np.linalg.cholesky(P_post)
        eps = rng.standard_normal(parts.shape)
        x_new = m_post + np.einsum("nij,nj->ni", Lq, eps)
        log_q = -0.5 * np.sum(eps**2, -1) - np.log(np.diagonal(Lq, axis1=1, axis2=2)).sum(-1)
        log_t = upf._log_gauss_chol(x_new - parts @ m.F.T, LQ)
        lw = f.log_w[0] + m.log_likelihood(Z[k], x_new) + log_t - log_q
        f.particles, f.covs = x_new[None], P_post[None]
        f.log_w = f._normalise(lw[None])
        f._resample_if_needed()
        f._estimate()
    return f.x


def cases() -> list[Case]:
    warnings.simplefilter("ignore", RuntimeWarning)
    exp = vs.experiment("jiang2023-straight", level=2)
    Z, x0 = exp.simulate(1, np.random.default_rng(0))
    Z, x0 = Z[0], x0[0]
    return [
        Case(
            "upf 500 particles x 100 epochs, vectorised",
            lambda: _run_vectorised(exp, Z, x0, "conditional"),
            group="upf",
            goal_s=1.0,
            repeat=7,
        ),
        Case(
            "upf 500 x 100, vectorised, paper's carried P",
            lambda: _run_vectorised(exp, Z, x0, "carried"),
            group="upf",
            goal_s=1.0,
            repeat=7,
        ),
        Case(
            "upf 500 x 100, loop of filterpy UKFs",
            lambda: _run_loop(exp, Z, x0),
            group="upf",
            baseline=True,
            repeat=3,
        ),
    ]
