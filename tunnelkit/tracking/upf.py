"""Unscented particle filter (Jiang et al. 2023, section 4.2.2; van der Merwe et al. 2000).

Every particle ``i`` carries a state sample ``X^i`` and its own covariance ``P^i``. One epoch:

1. time update per particle (eq. 51-52): ``m^i = Phi X^i``, ``P^i_pred = Phi P^i Phi^T + Q`` (for
   the linear ``f_1`` of eq. 40 the unscented transform is exact, so it is computed in closed form);
2. sigma points of ``N(m^i, P^i_pred)`` (eq. 46-50, redrawn after the prediction as filterpy's
   ``UnscentedKalmanFilter`` does), measurement update (eq. 53-58) -> proposal ``N(X_bar^i, P^i)``;
3. sample ``X^i_k ~ N(X_bar^i, P^i)`` (eq. 59);
4. weights (eq. 60-61): ``w^i *= p(Z | X^i) p(X^i | X^i_prev) / q(X^i | ...)``, in logs;
5. systematic resampling of ``(X^i, P^i)`` pairs when the effective sample size
   ``1 / sum(w^2)`` drops below ``resample_threshold * N`` (the paper resamples every epoch,
   ``resample_threshold = 1``);
6. output (eq. 62-63): weighted mean and spread of the particles.

Not in the paper, on by default: before step 3 the measurement passes a chi-square gate
(:mod:`tunnelkit.tracking.reopening`) on the innovation of the particle mixture, ``y = Z - z_bar``
with ``z_bar = sum_i w^i z_hat^i`` and ``S = sum_i w^i (Pzz^i + (z_hat^i - z_bar)(.)^T)`` (law of
total covariance over the particles' UKF predictions). A rejected measurement is a missed epoch
(particles drawn from the transition, weights unchanged). A reopened one (after ``reopen_after``
rejections in a row) widens every particle's predicted Gaussian, and the transition density its
weight uses, to the predicted cloud's covariance plus ``Q`` with the position block scaled by the
gate's inflation factor, so each particle's UKF update can reach the measurement (widening the
velocities too would let the particles pick random velocities from one position fix).

Everything is vectorised over particles *and* over any leading batch axis (independent
Monte-Carlo runs), with batched Cholesky factors and ``np.linalg.solve``; there is no Python
loop over particles. At the first epoch the transition density is the prior ``N(x0, P0)``.
filterpy's resamplers draw from numpy's global generator, so resampling here is a vectorised
systematic resampler on the explicit ``rng``.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
from filterpy.kalman import MerweScaledSigmaPoints

from .._checks import real_array
from .._domains import weights as check_weights
from .._validate import (
    finite_array,
    integer,
    nonnegative,
    positive,
    probability,
    real,
    rng_or_error,
)
from ..budget import check_elements
from .cv import STATE_DIM
from .registry import register
from .reopening import DEFAULT_GATE, DEFAULT_REOPEN_AFTER, REJECT, REOPEN, InnovationGate
from .virtual_station.filters import EstimatorBase, VsUKF
from .virtual_station.model import FAMILY, VsModel, check_model, check_prior, regularized_cholesky

__all__ = [
    "UnscentedParticleFilter",
    "effective_sample_size",
    "merwe_weights",
    "one_epoch_ess",
    "systematic_resample",
    "ukf_proposal",
    "ukf_proposal_reference",
]


def merwe_weights(
    n: int, alpha: float, beta: float, kappa: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """``(Wm, Wc, lambda)`` of eq. 47-50 for ``2n + 1`` sigma points (filterpy's Merwe weights).

    The weight arrays are read-only (the result is cached per ``(n, alpha, beta, kappa)``).
    """
    try:
        hash((n, alpha, beta, kappa))
    except TypeError:  # an array or a list: let the checks name it
        _check_merwe(n, alpha, beta, kappa)
    return _merwe_weights(n, alpha, beta, kappa)


@functools.lru_cache(maxsize=32, typed=True)  # filters ask every epoch; checked once per setting
def _merwe_weights(n, alpha, beta, kappa) -> tuple[np.ndarray, np.ndarray, float]:
    n, alpha, beta, kappa = _check_merwe(n, alpha, beta, kappa)
    lam = alpha**2 * (n + kappa) - n
    if n + lam <= 0:
        raise ValueError(f"alpha, kappa: n + lambda = {n + lam} must be > 0")
    pts = MerweScaledSigmaPoints(n, alpha=alpha, beta=beta, kappa=kappa)
    pts.Wm.setflags(write=False)
    pts.Wc.setflags(write=False)
    return pts.Wm, pts.Wc, lam


def _check_merwe(n, alpha, beta, kappa):
    n = integer("n", n, minimum=1)
    check_elements("n", 2 * n + 1, what=f"{2 * n + 1} sigma points' weights")
    alpha, beta, kappa = positive("alpha", alpha), nonnegative("beta", beta), real("kappa", kappa)
    return n, alpha, beta, kappa


def ukf_proposal(
    model: VsModel, m_pred, P_pred, z, *, alpha: float = 1.0, beta: float = 2.0, kappa: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Batched UKF measurement update (eq. 46-58): ``(X_bar, P)`` with shapes (..., 4), (..., 4, 4).

    ``m_pred`` (..., 4) and ``P_pred`` (..., 4, 4) are the predicted means and covariances,
    ``z`` (..., 2N) broadcasts against them.
    """
    check_model(model)
    m = finite_array("m_pred", m_pred)
    if m.ndim == 0 or m.shape[-1] != STATE_DIM:
        raise ValueError(f"m_pred: expected means (..., {STATE_DIM}), got shape {m.shape}")
    finite_array("P_pred", P_pred, ndim=None)
    if np.shape(P_pred)[-2:] != (STATE_DIM, STATE_DIM):
        raise ValueError(f"P_pred: expected covariances (..., 4, 4), got {np.shape(P_pred)}")
    if np.broadcast_shapes(real_array("z", z).shape[:-1], m.shape[:-1]) != m.shape[:-1]:
        raise ValueError(f"z: expected measurements (..., 2N) like m_pred, got {np.shape(z)}")
    return _ukf_update(model, m_pred, P_pred, z, alpha, beta, kappa)[:2]


def _ukf_update(model, m_pred, P_pred, z, alpha, beta, kappa):
    """:func:`ukf_proposal` plus the predicted measurement ``z_hat`` (..., 2N) and ``Pzz``."""
    n = m_pred.shape[-1]
    Wm, Wc, lam = merwe_weights(n, alpha, beta, kappa)
    L = regularized_cholesky((n + lam) * P_pred, name="UPF sigma-point covariance")
    offs = np.swapaxes(L, -1, -2)  # rows are the columns of L
    sig = m_pred[..., None, :] + np.concatenate(
        [np.zeros_like(offs[..., :1, :]), offs, -offs], axis=-2
    )
    Zs = model._h(sig)  # (..., 2n+1, m); the unchecked twins of hx / residual_z (own states)
    zhat = model.z_mean(Zs, Wm)
    dz = model._residual(Zs, zhat[..., None, :])
    dx = sig - m_pred[..., None, :]
    Pzz = np.einsum("s,...si,...sj->...ij", Wc, dz, dz) + model.R
    Pxz = np.einsum("s,...si,...sj->...ij", Wc, dx, dz)
    K = np.swapaxes(np.linalg.solve(Pzz, np.swapaxes(Pxz, -1, -2)), -1, -2)  # eq. 58
    innov = model._residual(np.broadcast_to(z, zhat.shape), zhat)
    m_post = m_pred + np.einsum("...ij,...j->...i", K, innov)  # eq. 54
    P_post = P_pred - K @ Pzz @ np.swapaxes(K, -1, -2)  # eq. 55
    return m_post, 0.5 * (P_post + np.swapaxes(P_post, -1, -2)), zhat, Pzz


def _mixture_d2(model: VsModel, w, zhat, Pzz, z) -> tuple[np.ndarray, np.ndarray]:
    """Squared Mahalanobis distance of ``z`` (B, 2N) under the particle mixture, (B,), and ``S``.

    ``w`` (B, N) are the particle weights, ``zhat`` (B, N, 2N) and ``Pzz`` (B, N, 2N, 2N) each
    particle's predicted measurement and its covariance (R included).
    """
    ref = zhat[:, :1, :]
    zbar = ref[:, 0, :] + np.einsum("bn,bnj->bj", w, model._residual(zhat, ref))
    dz = model._residual(zhat, zbar[:, None, :])
    S = np.einsum("bn,bnij->bij", w, Pzz) + np.einsum("bn,bni,bnj->bij", w, dz, dz)
    y = model.residual_z(z, zbar)
    return np.einsum("bi,bi->b", y, np.linalg.solve(S, y[..., None])[..., 0]), S


def ukf_proposal_reference(
    model: VsModel, particles, covs, z, *, alpha: float = 1.0, beta: float = 2.0, kappa: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """The same proposal with one filterpy ``UnscentedKalmanFilter`` per particle (predict, update).

    A slow loop kept as the reference the vectorised :func:`ukf_proposal` is tested and
    benchmarked against. ``particles`` (N, 4) are the previous samples, ``covs`` (N, 4, 4) theirs.
    """
    particles = finite_array("particles", particles, ndim=2)
    covs = finite_array("covs", covs, shape=(len(particles), STATE_DIM, STATE_DIM))
    if particles.shape[1] != STATE_DIM:
        raise ValueError(f"particles: expected shape (N, {STATE_DIM}), got {particles.shape}")
    out_m = np.empty_like(particles)
    out_P = np.empty_like(covs)
    for i in range(particles.shape[0]):
        f = VsUKF(model, particles[i], covs[i], alpha=alpha, beta=beta, kappa=kappa, gate=None)
        f.predict()
        f.update(z)
        out_m[i], out_P[i] = f.x, f.P
    return out_m, out_P


def effective_sample_size(weights) -> np.ndarray:
    """``1 / sum(w^2)`` over the last axis of the weights (normalised here: ``w / sum(w)``).

    ``weights`` must be finite, ``>= 0`` and have a positive sum in every row.
    """
    w = check_weights("weights", weights)
    return _ess(w / w.sum(axis=-1, keepdims=True))


def _ess(w: np.ndarray) -> np.ndarray:
    """:func:`effective_sample_size` of weights already normalised (inner loops)."""
    return 1.0 / np.sum(w * w, axis=-1)


def systematic_resample(weights, rng: np.random.Generator) -> np.ndarray:
    """Systematic resampling indices for normalised weights (..., N), vectorised over the batch.

    One uniform offset per row; ``idx[j]`` is the first particle whose cumulative weight exceeds
    ``(u + j) / N``. Rows are searched in one ``searchsorted`` by shifting row ``b`` by ``b``.
    """
    rng = rng_or_error("rng", rng)
    w = check_weights("weights", weights)
    n = w.shape[-1]
    flat = w.reshape(-1, n)
    b = flat.shape[0]
    cdf = np.cumsum(flat, axis=-1)
    cdf /= cdf[:, -1:]
    u = (rng.random((b, 1)) + np.arange(n)) / n
    shift = np.arange(b)[:, None]
    idx = np.searchsorted((cdf + shift).ravel(), (u + shift).ravel(), side="right").reshape(b, n)
    idx = np.minimum(idx - shift * n, n - 1)
    return idx.reshape(w.shape)


def _log_gauss_chol(d, L) -> np.ndarray:
    """``log N(d; 0, L L^T)`` without the ``2 pi`` constant, batched over ``d`` (..., n)."""
    if L.ndim == 2:
        u = np.linalg.solve(L, np.moveaxis(d, -1, 0).reshape(d.shape[-1], -1))
        u = np.moveaxis(u.reshape(d.shape[-1], *d.shape[:-1]), 0, -1)
        logdet = np.sum(np.log(np.diag(L)))
    else:
        u = np.linalg.solve(L, d[..., None])[..., 0]
        logdet = np.sum(np.log(np.diagonal(L, axis1=-2, axis2=-1)), axis=-1)
    return -0.5 * np.sum(u * u, axis=-1) - logdet


@register(FAMILY, "UPF")
class UnscentedParticleFilter(EstimatorBase):
    """Vectorised unscented particle filter on the model of eq. 40-45.

    ``x0`` is (4,) for one track or (B, 4) for ``B`` independent runs filtered together
    (``update`` then takes ``z`` of shape (B, 2N); a row with NaN is a missed epoch for that run).
    ``n_particles >= 1``; ``resample_threshold`` in (0, 1] is the effective-sample-size fraction
    that triggers resampling; ``rng`` is required. ``gate``/``reopen_after``: the innovation gate
    (module docstring); ``n_rejected`` counts rejections per run.
    """

    name = "UPF"

    def __init__(
        self,
        model: VsModel,
        x0,
        P0,
        *,
        rng: np.random.Generator,
        n_particles: int = 500,
        resample_threshold: float = 0.5,
        alpha: float = 1.0,
        beta: float = 2.0,
        kappa: float = 0.0,
        proposal: str = "conditional",
        gate: float | None = DEFAULT_GATE,
        reopen_after: int = DEFAULT_REOPEN_AFTER,
    ) -> None:
        self.model = check_model(model)
        if proposal not in ("conditional", "carried"):
            raise ValueError(f"proposal: expected 'conditional' or 'carried', got {proposal!r}")
        self.proposal = proposal
        self.rng = rng_or_error("rng", rng)
        self.n_particles = integer("n_particles", n_particles, minimum=1)
        self.resample_threshold = probability(
            "resample_threshold", resample_threshold, open_interval=False
        )
        if self.resample_threshold == 0:
            raise ValueError("resample_threshold: must be > 0")
        self.alpha, self.beta, self.kappa = positive("alpha", alpha), float(beta), float(kappa)
        nonnegative("beta", beta), real("kappa", kappa)
        merwe_weights(STATE_DIM, self.alpha, self.beta, self.kappa)
        x0 = finite_array("x0", x0)
        self._batched = x0.ndim == 2
        x0b = np.atleast_2d(x0)
        if x0b.ndim != 2 or x0b.shape[1] != STATE_DIM:
            raise ValueError(f"x0: expected shape (4,) or (B, 4), got {x0.shape}")
        _, P0 = check_prior(x0b[0], P0)
        self.batch = x0b.shape[0]
        self.gate = InnovationGate(gate, reopen_after=reopen_after, batch=self.batch)
        L0 = np.linalg.cholesky(P0)
        N = self.n_particles
        # particles, their covariances and the predicted copies: about 3 x 20 floats each
        check_elements("n_particles", self.batch * N * 60, what=f"{self.batch} x {N} particles")
        # step (1): X_0^i ~ p(X_0) = N(x0, P0), each particle with covariance P0
        self.particles = (
            x0b[:, None, :] + self.rng.standard_normal((self.batch, N, STATE_DIM)) @ L0.T
        )
        self.covs = np.broadcast_to(P0, (self.batch, N, STATE_DIM, STATE_DIM)).copy()
        self.log_w = np.full((self.batch, N), -np.log(N))
        # the first epoch's "transition" is the prior itself
        self._m_pred = np.broadcast_to(x0b[:, None, :], self.particles.shape).copy()
        self._P_pred = self.covs.copy()
        self._trans_mean = self._m_pred
        self._trans_chol = L0
        self._pending = True
        self._LQ = regularized_cholesky(self.model.Q, name="Q")
        self.resampled = np.zeros(self.batch, dtype=int)  # resampling count per run
        self._estimate()

    # -- outputs (eq. 62-63) --------------------------------------------------------------------
    @property
    def weights(self) -> np.ndarray:
        w = np.exp(self.log_w)
        return w if self._batched else w[0]

    def _estimate(self) -> None:
        w = np.exp(self.log_w)
        xb = np.einsum("bn,bni->bi", w, self.particles)
        d = self.particles - xb[:, None, :]
        Pb = np.einsum("bn,bni,bnj->bij", w, d, d)
        Pb = 0.5 * (Pb + np.swapaxes(Pb, -1, -2))
        self._x, self._P = xb, Pb

    @property
    def x(self) -> np.ndarray:
        return self._x if self._batched else self._x[0]

    @property
    def P(self) -> np.ndarray:
        return self._P if self._batched else self._P[0]

    @property
    def position(self) -> np.ndarray:
        return self.x[..., :2].copy()

    @property
    def n_rejected(self):
        """Measurements the gate rejected: an int, or one count per run when batched."""
        n = self.gate.n_rejected
        return n if self._batched else int(n[0])

    @property
    def n_reopened(self):
        """Measurements taken with an inflated prior after ``reopen_after`` rejections in a row."""
        n = self.gate.n_reopened
        return n if self._batched else int(n[0])

    # -- filter steps -----------------------------------------------------------------------------
    def predict(self) -> None:
        """Time update of every particle's Gaussian (eq. 51-52)."""
        if self._pending:  # predict twice without an update: the skipped epoch was a miss
            self.update(None)
        F, Q = self.model.F, self.model.Q
        self._m_pred = self.particles @ F.T
        if self.proposal == "carried":  # eq. 52 as printed: the particle's own covariance grows
            self._P_pred = F @ self.covs @ F.T + Q
        else:  # X^i_{k-1} is a known sample: its successor is spread by Q alone
            self._P_pred = np.broadcast_to(Q, self.covs.shape).copy()
        self._trans_mean = self._m_pred
        self._trans_chol = self._LQ
        self._pending = True

    def _check_z(self, z) -> None:  # one row per run when the filter runs a batch
        self._z_rows(z)

    def _z_rows(self, z) -> tuple[np.ndarray, np.ndarray]:
        m = self.model.dim_z
        if z is None:
            return np.zeros((self.batch, m)), np.zeros(self.batch, bool)
        try:
            Z = np.asarray(z, dtype=float)
        except (TypeError, ValueError) as exc:
            raise TypeError(f"z: expected numbers or None, got {type(z).__name__}") from exc
        want = (self.batch, m) if self._batched else (m,)
        if Z.shape != want:
            raise ValueError(f"z: expected shape {want}, got {Z.shape}")
        Z = np.atleast_2d(Z)
        ok = np.all(np.isfinite(Z), axis=-1)
        if not np.all(ok):
            warnings.warn(
                f"UPF: {int(np.sum(~ok))} measurement(s) contain NaN/inf; those epochs are "
                f"skipped (predict only)",
                RuntimeWarning,
                stacklevel=3,
            )
        return np.where(ok[:, None], Z, 0.0), ok

    def update(self, z) -> None:
        """Proposal, sampling, weighting and (if the ESS is low) resampling (eq. 53-61)."""
        if not self._pending:
            raise RuntimeError(
                "UPF.update: call predict() before a second update at the same epoch"
            )
        Z, ok = self._z_rows(z)
        self._pending = False
        rng = self.rng
        eps = rng.standard_normal(self.particles.shape)
        # missed epoch: sample from the transition density, weights unchanged
        trans_chol = self._trans_chol
        if trans_chol.ndim == 2:
            prior_draw = self._trans_mean + eps @ trans_chol.T
        else:
            prior_draw = self._trans_mean + np.einsum("...ij,...j->...i", trans_chol, eps)
        new_p = prior_draw
        new_P = self._P_pred
        log_w = self.log_w
        sel = np.flatnonzero(ok)
        if sel.size:
            m_pred, P_pred = self._m_pred[sel], self._P_pred[sel]
            t_mean = self._trans_mean[sel]
            tc = trans_chol if trans_chol.ndim == 2 else trans_chol[sel]
            zb = Z[sel][:, None, :]
            upd = _ukf_update(self.model, m_pred, P_pred, zb, self.alpha, self.beta, self.kappa)
            m_post, P_post = upd[:2]
            if self.gate.enabled:
                lw = log_w[sel]
                mx = np.max(lw, axis=-1, keepdims=True)
                live = np.isfinite(mx)  # a run whose weights all vanished gates on uniform ones
                w = np.where(live, np.exp(lw - np.where(live, mx, 0.0)), 1.0)
                w = w / np.sum(w, axis=-1, keepdims=True)
                d2, S = _mixture_d2(self.model, w, upd[2], upd[3], Z[sel])
                verdict = self.gate.judge(d2, self.model.dim_z, rows=sel)
                re = np.flatnonzero(verdict == REOPEN)
                if re.size:  # widen every particle's prediction to the inflated cloud
                    alpha = self.gate.inflation(d2[re], self.model.dim_z, S[re], self.model.R)
                    mean = np.einsum("bn,bni->bi", w[re], m_pred[re])
                    dm = m_pred[re] - mean[:, None, :]
                    Pc = np.einsum("bn,bni,bnj->bij", w[re], dm, dm) + self.model.Q
                    g = np.ones((re.size, STATE_DIM))
                    g[:, :2] = np.sqrt(alpha)[:, None]  # the position block only
                    Pw = g[:, :, None] * 0.5 * (Pc + np.swapaxes(Pc, -1, -2)) * g[:, None, :]
                    P_pred = P_pred.copy()
                    P_pred[re] = Pw[:, None]
                    tc = np.broadcast_to(tc, (sel.size, 1, *tc.shape[-2:])).copy()
                    tc[re] = regularized_cholesky(Pw, name="UPF reopened prior")[:, None]
                    m_post, P_post = _ukf_update(
                        self.model, m_pred, P_pred, zb, self.alpha, self.beta, self.kappa
                    )[:2]
                keep = verdict != REJECT  # rejected rows stay missed epochs
                sel, m_pred, P_pred, t_mean, zb = (
                    sel[keep],
                    m_pred[keep],
                    P_pred[keep],
                    t_mean[keep],
                    zb[keep],
                )
                m_post, P_post = m_post[keep], P_post[keep]
                tc = tc if tc.ndim == 2 else tc[keep]
        if sel.size:
            Lq = regularized_cholesky(P_post, name="UPF proposal covariance")
            e = eps[sel]
            x_new = m_post + np.einsum("...ij,...j->...i", Lq, e)  # eq. 59
            log_q = -0.5 * np.sum(e * e, axis=-1) - np.sum(
                np.log(np.diagonal(Lq, axis1=-2, axis2=-1)), axis=-1
            )
            log_trans = _log_gauss_chol(x_new - t_mean, tc)
            log_lik = self.model.log_likelihood(zb, x_new)
            lw = log_w[sel] + log_lik + log_trans - log_q  # eq. 60
            new_p = new_p.copy()
            new_P = new_P.copy()
            log_w = log_w.copy()
            new_p[sel], new_P[sel], log_w[sel] = x_new, P_post, lw
        self.particles, self.covs = new_p, new_P
        self.log_w = self._normalise(log_w)
        self._resample_if_needed()
        self._estimate()

    def _normalise(self, log_w) -> np.ndarray:
        """eq. 61 in logs; a run whose weights all vanished restarts from uniform weights (warns)."""
        log_w = np.where(np.isnan(log_w), -np.inf, log_w)
        mx = np.max(log_w, axis=-1, keepdims=True)
        dead = ~np.isfinite(mx[:, 0])
        if np.any(dead):
            warnings.warn(
                f"UPF: all particle weights vanished in {int(dead.sum())} run(s); weights reset "
                f"to uniform",
                RuntimeWarning,
                stacklevel=3,
            )
            log_w = np.where(dead[:, None], 0.0, log_w)
            mx = np.where(dead[:, None], 0.0, mx)
        log_w = log_w - mx
        return log_w - np.log(np.sum(np.exp(log_w), axis=-1, keepdims=True))

    def _resample_if_needed(self) -> None:
        w = np.exp(self.log_w)
        low = _ess(w) < self.resample_threshold * self.n_particles - 1e-9
        if self.resample_threshold >= 1.0:
            low[:] = True
        if not np.any(low):
            return
        sel = np.flatnonzero(low)
        idx = systematic_resample(w[sel], self.rng)
        self.particles[sel] = np.take_along_axis(self.particles[sel], idx[..., None], axis=1)
        self.covs[sel] = np.take_along_axis(self.covs[sel], idx[..., None, None], axis=1)
        self.log_w[sel] = -np.log(self.n_particles)
        self.resampled[sel] += 1

    @classmethod
    def run(cls, model, Z, x0, P0, *, rng=None, **options) -> np.ndarray:
        """All runs filtered together (batch axis), epochs in a loop: estimates (R, T, 4)."""
        if rng is None:
            raise TypeError("rng: the UPF needs an explicit numpy.random.Generator")
        real_array("Z", Z, ndim=3), finite_array("x0", x0)
        Z = np.asarray(Z, dtype=float)
        f = cls(model, np.asarray(x0, dtype=float), P0, rng=rng, **options)
        out = np.empty((*Z.shape[:2], STATE_DIM))
        for k in range(Z.shape[1]):
            if k > 0:
                f.predict()
            f.update(Z[:, k])
            out[:, k] = f._x
        return out


def one_epoch_ess(
    model: VsModel,
    Z,
    x0,
    P0,
    *,
    rng: np.random.Generator,
    n_particles: int = 200,
    proposal: str = "conditional",
    epochs: int | None = None,
) -> np.ndarray:
    """Effective sample size of *one* epoch's weights, epoch by epoch, for one run ``Z`` (T, 2N).

    The filter never resamples; after each epoch its weights are reset to uniform, so the ESS at
    epoch k measures how well the proposal of that epoch alone matches the posterior (the
    diagnostic of the eq. 52 trap in notebook 05). Returns (epochs,).
    """
    real_array("Z", Z, ndim=2)
    Z = np.asarray(Z, dtype=float)
    T = Z.shape[0] if epochs is None else integer("epochs", epochs, minimum=1, maximum=Z.shape[0])
    f = UnscentedParticleFilter(
        model,
        x0,
        P0,
        rng=rng,
        n_particles=n_particles,
        proposal=proposal,
        resample_threshold=1e-9,
    )
    ess = np.empty(T)
    for k in range(T):
        f.step(Z[k], first=(k == 0))
        ess[k] = _ess(f.weights)
        f.log_w[:] = -np.log(f.n_particles)
    return ess
