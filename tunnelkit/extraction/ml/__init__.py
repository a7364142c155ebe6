"""Joint maximum-likelihood path extraction on the full eq. 1 model (ours, beyond Italiano et al. 2026).

Model
-----
With white circular Gaussian noise of power ``sigma^2`` per sample, the log-likelihood of the
tensor ``H`` (M x Nf x Nt) is, up to constants, ``-||H - sum_l c_l X_l||^2 / sigma^2`` with the
rank-one atoms of eq. 1

    X_l = a(u_l, w_l) o f(mu_f,l) o t(mu_t,l),
    a_m = exp(j k0 (||q_l - p_m|| - ||q_l||)),  f_s = exp(j s mu_f,l),  t_k = exp(j k mu_t,l),

``q_l = u_l / w_l`` the wave origin in the array's local frame (elements ``p_m`` in the plane
``z = 0``, ``p_0 = 0``), ``k0 = 2 pi fc / c`` and ``c_l`` the complex gain (``sqrt(P_t) alpha_l``).

Parametrisation
---------------
Per path five real numbers ``theta_l = (u_x, u_y, w, mu_f, mu_t)``: the direction cosines in the
array plane, the curvature ``w = 1 / kappa`` and the two Vandermonde frequencies
(``d = -c mu_f / (2 pi Df)``, ``v = c mu_t / (2 pi fc T0)``). Since ``p_z = 0``, the spatial phase
depends on ``u`` only through ``u . p = u_x p_x + u_y p_y``; with ``D = ||u - w p|| =
sqrt(1 - 2 w u.p + w^2 |p|^2)`` (> ``u_z`` > 0 in the front half-space) it reads, in a form that is
smooth through the far field ``w = 0``,

    psi_m = k0 (||q - p_m|| - ||q||) = k0 N / Q,   N = w |p|^2 - 2 u.p,   Q = 1 + D,

    d psi / d u_x = k0 p_x (-2 / Q + N w / (Q^2 D))         (likewise u_y with p_y),
    d psi / d w   = k0 (|p|^2 / Q - N (w |p|^2 - u.p) / (Q^2 D)).

The feasible set is ``|u| <= U_MAX = 0.99999`` (front half-space up to 0.26 deg from end-fire) and
``0 <= w <= W_MAX``; every step is projected onto it, so no estimate leaves the front half-space,
and ``w = 0`` is an exact far-field wave (reported as ``kappa = NaN``).

Variable projection
-------------------
For fixed ``theta`` the gains are linear least squares: ``c = G^{-1} b`` with ``b_l = <X_l, H>``
and the Gram ``G = (A^H A) * (F^H F) * (T^H T)`` (Hadamard product of the three modes' Grams,
because inner products of rank-one tensors factorise). The concentrated cost is
``phi(theta) = ||H||^2 - b^H G^{-1} b = ||r||^2`` (``r = P_perp h``, ``P_perp`` the projector off
the span of the atoms). Its Gauss-Newton model uses Kaufman's simplification of the
Golub-Pereyra Jacobian, ``J = -P_perp D`` with ``D_i = c_l dX_l / d theta_i`` (one rank-one term
per parameter). Then

    J^H J = D^H D - (D^H B) G^{-1} (B^H D),      J^H r = -D^H r = -conj(c_l) (<dX_i, H> - (B^H dX_i)^H c),

every inner product again a Hadamard product of mode Grams, and ``<dX_i, H>`` a contraction of
``H`` with mode vectors: ``H``, stored once as an (M Nt) x Nf matrix, is multiplied by the
``2L`` frequency vectors ``conj(f_l)``, ``conj(s f_l)`` (one BLAS product with a long inner
dimension, ``M Nf Nt 2L`` products), then each path meets its time and spatial vectors (small).
One iteration therefore costs one pass over ``H`` and a ``5L x 5L`` solve; no
``(M Nf Nt) x 5L`` matrix is ever formed. Levenberg-Marquardt: ``(Re J^H J + lambda diag(Re J^H J)) delta = Re(D^H r)``, a step
is kept only if the cost drops, ``lambda`` shrinks by 3 on success and grows by 4 on failure.

Stopping rule
-------------
The Newton decrement ``g^T (Re J^H J)^{-1} g`` (``g = Re D^H r``) is the cost decrease a full
Gauss-Newton step promises; in units of ``sigma^2`` it is the squared distance to the optimum
measured in standard deviations of the estimate (the Fisher information of the concentrated
model is ``2 Re(J^H J) / sigma^2``). The iteration stops when it is below ``STEP_TOL``
(0.01 sigma in every direction together), or when ``lambda`` exceeds ``1e10`` (no descent left
at working precision: the cost is resolved to about ``1e-5 sigma^2``).

Noise floor and basin test
--------------------------
The noise power is estimated without the model from the time-mode unfolding ``H_(3)`` (Nt x
M Nf): the signal occupies at most ``L`` of its ``Nt`` dimensions, so the ``Nt - L`` smallest
eigenvalues of ``H_(3) H_(3)^H`` hold noise only, ``sigma^2 ~ sum / ((Nt - L)(M Nf - L))`` (the
space mode is used when ``L >= Nt``); or it is given by the caller. The estimate runs low by up
to about ``L sqrt(Nt / (M Nf)) / (Nt - L)`` (1 % for five paths) when paths share a Doppler bin
(the ``L`` largest eigenvalues then include noise maxima); half of that is added to the
threshold below. At the maximum-likelihood
estimate of the right model, ``2 ||r||^2 / sigma^2`` is chi-square with ``2N - 5L`` degrees of
freedom (``N = M Nf Nt``, the gains included), so ``rho = ||r||^2 / ((N - 2.5 L) sigma^2)`` is
``1 +- sqrt(1 / N)``. A fit with ``rho`` above ``1 + RHO_Z sqrt(1 / N + 1 / N_sigma)`` (plus
the allowance) has not found the right basin
(a path missed, merged or counted twice) and is re-seeded, SAGE-like, each move kept only if
the likelihood rises:

- *merge and split* (once), when two atoms are nearly collinear (``|G_ij| / sqrt(G_ii G_jj) >
  0.9``: one path counted twice, usually because two others closer than a beamwidth were
  fitted as one): the weaker of the two out, the ``L - 1`` fitted, then each of them in turn
  split into two halves an eighth of a beamwidth apart and all ``L`` fitted, until the basin
  test passes; then, or otherwise, alternating:
- *birth and death*: one path more, sought in the pure residual ``r``, all ``L + 1`` fitted
  jointly, the least significant one out and the ``L`` fitted again;
- *replace the weakest*: the path whose removal raises the cost least (``|c_l|^2 /
  [G^{-1}]_ll``) is dropped and sought again in ``H`` less the other paths (the residual plus
  its own contribution).

Residual test and re-initialisation on the residual
---------------------------------------------------
The energy test above spreads a wrong basin's structured residual over all ``N`` dimensions: at
long range, where the ceiling, road and wall images lie a fraction of a beamwidth and of the
delay resolution from the line of sight, a fit that merged two of them and counted a third twice
leaves thousands of noise powers in the residual and still passes it. The residual test of
:mod:`.residual` looks at the largest peak of the residual's single-path periodogram instead
(exponential with mean 1 per grid point under noise; threshold at the false-alarm rate
``FALSE_ALARM`` = 1 %, calibrated by simulating the statistic on noise-only tensors of the
same array and shape: :func:`~.residual.calibrated_threshold`). The same statistic is the
generalised likelihood-ratio test (GLRT) of one path more, so it is also the detection test of
each path: ``MLFit.detected`` marks the paths whose significance passes it, and the model
order (:func:`~.paths.ml_order`) adds paths while the residual still holds one. While it fails, a path is started at the peak (grid direction, delay
and Doppler, a curvature scan and a single-source fit) and several starts are made from it —
birth and death, the new path in place of the one whose atom is most like it or of the weakest
(the weaker of two nearly collinear atoms, if any), and the nearest path split in two in place
of the weakest (halves an eighth of a beamwidth apart along each axis, and along the line from
the nearest path to the peak, full and half length: a merged pair leaves its missing energy on
that side) — each given ``RANK_ITER`` iterations, ranked by the likelihood, the best fitted
to convergence and kept if the likelihood rises (SAGE / RIMAX re-initialisation; the moves on
``rho`` below follow when the energy test still fails). The first fit is screened after
``SCREEN_ITER`` iterations: one not converged by then whose residual fails the test (a fit
crawling in a wrong basin, typically clustered long-range paths merging) is re-initialised at
once, its own continuation one of the ranked starts; one that passes goes on to ``max_iter``
exactly as without the screen (the iteration is resumable). When a path is still below the noise after that (the fit counts one path too few elsewhere:
at long range two images merged into one strong path), the weak path is dropped and each other
path in turn split in two (``WEAK_SPLITS``: an eighth of a beamwidth and 2.5 times that, along
each axis), the starts ranked after ``RANK_ITER`` iterations, the best fitted and kept if the
cost falls by more than the detection threshold of one path. The same move runs (up to
``SPLIT_ROUNDS`` times) when two paths are closer than ``RESOLVE_Z`` standard deviations of
their difference: at long range and at low SNR the search also ends with a cluster merged and a
path counted twice (two atoms side by side with large opposite gains, each far above the
noise); the less significant of the pair is the path dropped, and a split is kept when it lowers
the cost by more than ``PAIR_GAIN`` noise powers (the model order is the same, so the more
likely basin is the estimate). ``MLFit.fit_ok`` (and
``PathEstimates.fit_ok``) is the verdict: the periodogram peak and ``rho`` below their
thresholds, every path above the noise (``MIN_SIGNIFICANCE``) and every two paths resolved:
further apart than ``RESOLVE_Z`` standard deviations of their difference (the statistical
resolution limit, :func:`~.fitting.pair_separation`: below it the likelihood has no separate
peak for each and the errors leave the local bound however well the search does) and
every close pair resolved by the pair test (:func:`~.resolution.pair_test`: the GLRT of one path,
the two merged and every path fitted again, against two, at a 1 % false-alarm rate from its
null distribution by Monte-Carlo; ``MLFit.unresolved`` and ``PathEstimates.unresolved`` name
each path's partner in a pair it fails);
``MLFit.reason`` names the tests a fit failed. ``search="basic"`` skips the
re-initialisation (the route before it, for comparison).

A search takes the dominant rank-one term of its tensor (power iterations), the periodogram peaks
of its frequency and time vectors for ``mu_f`` and ``mu_t``, a far-field beam scan of its spatial
vector for ``u``, a 1-D scan of ``w`` and a local single-source fit.

Each path's significance ``|c_l|^2 / ([G^{-1}]_ll sigma^2)`` is its log-likelihood ratio; a path
below ``MIN_SIGNIFICANCE`` is indistinguishable from noise: it is returned with ``valid = False``
and a :class:`MLDetectionWarning` says how many of the ``n_paths`` were found. If the fit cannot
improve on its start it keeps the start and warns (:class:`MLConvergenceWarning`); so does a
fit whose residual still fails the basin test after the re-seedings.

References: Fleury et al., "Channel parameter estimation in mobile radio environments using the
SAGE algorithm", IEEE JSAC 17(3), 1999; Richter, "Estimation of radio channel parameters: models
and algorithms (RIMAX)", PhD thesis, TU Ilmenau, 2005; Golub & Pereyra, SIAM J. Numer. Anal.
10(2), 1973; Kaufman, BIT 15, 1975.

Modules, each importing only from the ones above it:

- :mod:`.model` — :class:`Problem` (the concentrated cost and its Gauss-Newton model), the
  feasible set, the noise floor;
- :mod:`.lm` — Levenberg-Marquardt and its stopping rule (:func:`~.lm.lm_fit`);
- :mod:`.search` — the starts: one path from a (residual) tensor, successive cancellation,
  starts from estimates;
- :mod:`.residual` — the residual test (periodogram peak against its noise-only distribution);
- :mod:`.resolution` — the statistical resolution limit: per-path separations in standard
  deviations, significance, the per-path verdict :func:`resolvable`; the threshold in SNR by
  the method of interval errors (:func:`snr_threshold`, :func:`outlier_probability`) and the
  per-path threshold region :func:`below_threshold` (``PathEstimates.below_threshold``); the
  pair test :func:`pair_test` (``PathEstimates.unresolved``);
- :mod:`.fitting` — the basin test and the re-seedings: :func:`fit_ml`, :class:`MLFit`;
- :mod:`.wideband` — :class:`WidebandProblem`, the model with the spatial-wideband term (each
  element its own delay across the band), a :class:`Problem` the fit runs on unchanged;
- :mod:`.paths` — :func:`ml_paths` (``wideband=True``: the eq. 1 fit refined on that model) and
  :func:`estimates_from_fit`.

The shared numerics (the spatial phase, the damped step, the decrement, ``MIN_SIGNIFICANCE``)
live in :mod:`tunnelkit.extraction.numerics`.
"""

from ..numerics import spatial_phase
from .fitting import (
    MAX_ITER,
    SEARCHES,
    MLConvergenceWarning,
    MLDetectionWarning,
    MLFit,
    fit_ml,
    fit_problem,
    pair_separation,
)
from .model import Problem, noise_floor, project_feasible
from .paths import estimates_from_fit, ml_order, ml_paths, physical
from .residual import FALSE_ALARM, calibrated_threshold, peak_null, peak_threshold, residual_peak
from .resolution import (
    OUTLIER_RATE,
    PAIR_FALSE_ALARM,
    PAIR_LLR,
    PAIR_TEST_Z,
    RESOLVE_Z,
    below_threshold,
    closest_pair,
    outlier_probability,
    pair_test,
    resolvable,
    separations,
    snr_threshold,
)
from .search import (
    check_start,
    complete_paths,
    path_from_peak,
    search_path,
    start_from_estimates,
)
from .wideband import WidebandProblem

__all__ = [
    "FALSE_ALARM",
    "MAX_ITER",
    "OUTLIER_RATE",
    "PAIR_FALSE_ALARM",
    "PAIR_LLR",
    "PAIR_TEST_Z",
    "RESOLVE_Z",
    "SEARCHES",
    "MLConvergenceWarning",
    "MLDetectionWarning",
    "MLFit",
    "Problem",
    "WidebandProblem",
    "below_threshold",
    "calibrated_threshold",
    "check_start",
    "closest_pair",
    "complete_paths",
    "estimates_from_fit",
    "fit_ml",
    "fit_problem",
    "ml_order",
    "ml_paths",
    "noise_floor",
    "outlier_probability",
    "pair_separation",
    "pair_test",
    "path_from_peak",
    "peak_null",
    "peak_threshold",
    "physical",
    "project_feasible",
    "residual_peak",
    "resolvable",
    "search_path",
    "separations",
    "snr_threshold",
    "spatial_phase",
    "start_from_estimates",
]
