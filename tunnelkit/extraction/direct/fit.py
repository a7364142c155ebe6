"""The direct fit: every atom of the visibility model tied to one UE position, one clock bias
and (optionally) one speed.

On the ray-traced channel the line of sight, the road bounce, the road markings' and the
second-order bounces of the paper's 10 x 10 arrive within one beam width and one delay
resolution cell of each other. Fitted one atom per path (:class:`~.visibility.MaskedProblem`),
the atoms trade energy and places: started 0.1 m off the truth, the atom started on the line of
sight ends degrees away on several epochs (``docs/results/traced-models.md``). The image method
says they cannot move apart: every path's wave origin is the UE mirrored in the surfaces it
bounced off, an affine map of the UE's position (:func:`image_maps`), its delay its length plus
the receiver's clock bias, its Doppler the UE's velocity mirrored the same way.
:class:`DirectProblem` is eq. 1 with the visibility masks in which every atom's direction,
curvature, delay and Doppler are those of the UE at ``(x, y)`` (the height the prediction's)
with a clock bias ``b`` [m] and a speed along the message's heading; the gains stay free and
are concentrated out as in eq. 1's fit. Three or four parameters, whatever the number of atoms.

The ray tracer's diffuse scattering near a wall arrives within one delay cell of the line of
sight from a spread of directions: rank one over the elements and over the tones, but no
point source (one free eq. 1 atom leaves a third to a half of it). A **diffuse atom** models it:
a delay and a Doppler common to every element and a free gain on each element; ``direct_fix``
admits up to ``diffuse`` of them by a test against the noise (:func:`diffuse_threshold`), the
gains concentrated out with the tied atoms'. Two more parameters per atom.

:func:`direct_fix` fits them from a prediction: the clock bias on a grid over its support at the
predicted position, then Levenberg-Marquardt (:func:`scipy.optimize.least_squares`) on the
residual with the gains projected out, first ``(x, y, b)``, then with the speed. A fit that does
not converge, or that ends further than ``gate`` from the prediction (the range and the clock bias
trade off along the tunnel), is flagged (``DirectFix.ok`` False), never returned as valid.

The model is built once, at the prediction: which facets and road markings are seen, and by
which elements, is the prediction's. On the model's own tensor a prediction 0.1 m off sideways
changed the masks of 5-57 element-path pairs or the second-order list at the epochs checked
(0.1 m along the tunnel changes fewer: none at two epochs, 5 pairs at two others), and the fit
then landed up to 1.8 m off; rebuilding the model at each fit, or holding the paths seen from a
ring around the prediction, was tried and did not remove it (``docs/results/traced-models.md``). Used under the tracker by :mod:`tunnelkit.design.traceddirect`.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import chi2

from ..._physical import speeds
from ..._validate import boolean, finite_array, instance, integer, positive, record, sequence
from ...arrays import ArrayGeometry
from ...channel import SRSConfig
from ...constants import C
from ...propagation import SECOND_ORDER, Path, Tunnel3D
from ..decomposition import check_tensor
from ..numerics import spatial_phase_unchecked
from .visibility import MaskedProblem, predicted_model

__all__ = [
    "DirectFix",
    "DirectProblem",
    "diffuse_share",
    "diffuse_start",
    "diffuse_threshold",
    "direct_fix",
    "image_maps",
]

#: [m] the largest UE height above the road and the largest gate :func:`direct_fix` takes
MAX_HEIGHT_M, MAX_GATE_M = 20.0, 1000.0
#: the most diffuse atoms :func:`direct_fix` selects, and the nominal false-alarm probability of
#: the test that admits each (:func:`diffuse_threshold`)
MAX_DIFFUSE, DIFFUSE_FALSE_ALARM = 4, 1e-3
#: the delay-Doppler grid :func:`diffuse_start` searches: the tones zero-padded this many times,
#: the symbols to at least this many
TONE_PAD, MIN_SYMBOL_BINS = 4, 64
#: the most elements, tones or symbols a tensor's side has in :func:`diffuse_threshold`
MAX_TENSOR_SIDE = 65_536
#: [m] the clock-bias grid's step (an eighth to a twelfth of the delay cell ``c / B`` of the
#: presets' 98-400 MHz: 0.75-3 m)
B_STEP = 0.25


def image_maps(tunnel, paths) -> tuple[np.ndarray, np.ndarray]:
    """``(R, t)``, (L, 3, 3) and (L, 3): each path's wave origin as ``R[l] @ ue + t[l]`` (the line
    of sight: the identity; a reflection: the mirror in its surface's plane; a second-order path
    ``"first > second"``: the mirror in ``first`` then in ``second``)."""
    instance("tunnel", tunnel, Tunnel3D)
    paths = sequence("paths", paths)
    planes = {s.name: s.plane for s in tunnel.surfaces}
    R, t = np.tile(np.eye(3), (len(paths), 1, 1)), np.zeros((len(paths), 3))
    for i, p in enumerate(paths):
        if not isinstance(p, Path):
            raise TypeError(f"paths: expected traced Paths, got {type(p).__name__}")
        names = [] if p.kind == "los" else [n.strip() for n in p.surface.split(">")]
        if (p.kind == SECOND_ORDER) != (len(names) == 2) or any(n not in planes for n in names):
            raise ValueError(f"paths: {p.kind} off {p.surface!r} is not one of the tunnel's")
        for n in names:
            h = np.eye(3) - 2.0 * np.outer(planes[n].normal, planes[n].normal)
            R[i], t[i] = h @ R[i], h @ t[i] - 2.0 * planes[n].offset * planes[n].normal
    return R, t


def _parameters(name: str, x, diffuse: int = 0) -> np.ndarray:
    """``x`` checked as ``(x, y, b)`` [m] or ``(x, y, b, speed)`` [m, m/s], then ``(mu_f,
    mu_t)`` [rad] per diffuse atom (``diffuse`` of them)."""
    x = finite_array(name, x, ndim=1)
    if x.size - 2 * diffuse not in (3, 4):
        tail = f" then (mu_f, mu_t) of {diffuse} diffuse atoms" if diffuse else ""
        raise ValueError(
            f"{name}: expected (x, y, b) or (x, y, b, speed){tail}, got {x.size} values"
        )
    if x.size - 2 * diffuse == 4:
        speeds(name, x[3])
    return x


class DirectProblem(MaskedProblem):
    """The tensor ``H`` at ``array`` (an :class:`~tunnelkit.arrays.ArrayGeometry`) with the radio
    ``srs``: eq. 1 with ``mask`` (M, L) (:func:`~.visibility.visible_paths`), atom ``l``'s wave
    origin ``R[l] @ ue + t[l]`` (:func:`image_maps`) for the UE at ``(x, y, height)`` moving at
    ``velocity`` (3,), its delay its length plus the clock bias ``b`` [m] (module docstring). The
    parameters ``x``: ``(x, y, b)`` [m], or ``(x, y, b, speed)`` with the UE moving at ``speed``
    [m/s] along ``velocity``'s direction; then, with ``diffuse`` atoms, each one's ``(mu_f,
    mu_t)``: a delay and a Doppler common to every element, its gain free on each element (the
    dense multipath, module docstring), concentrated out with the tied atoms' gains."""

    def __init__(self, H, array, srs, mask, maps, height: float, velocity, *, diffuse: int = 0):
        instance("array", array, ArrayGeometry)
        self.srs = instance("srs", srs, SRSConfig)
        if np.ndim(H) != 3 or np.shape(H)[0] != array.M:
            raise ValueError(f"H: expected ({array.M}, Nf, Nt), the array's elements first, "
                             f"got shape {np.shape(H)}")  # fmt: skip
        super().__init__(H, array.local, srs.fc, mask)
        if not isinstance(maps, tuple | list) or len(maps) != 2:
            raise TypeError(f"maps: expected image_maps' (R, t), got {type(maps).__name__}")
        L = self.mask.shape[1]
        self.R = finite_array("maps", maps[0], shape=(L, 3, 3))
        self.t = finite_array("maps", maps[1], shape=(L, 3))
        self.height = float(finite_array("height", height, ndim=0))
        if not 0.0 < self.height <= MAX_HEIGHT_M:
            raise ValueError(
                f"height: a UE height above the road, at most {MAX_HEIGHT_M:g} m, got {height}"
            )
        self.velocity = speeds("velocity", finite_array("velocity", velocity, shape=(3,)))
        self.diffuse = integer("diffuse", diffuse, minimum=0, maximum=MAX_DIFFUSE)
        speed = float(np.linalg.norm(self.velocity))
        self.heading = self.velocity / speed if speed > 0 else np.zeros(3)
        self.origin, self.frame = array.origin, array.R

    def atoms(self, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """eq. 1's ``(theta, mu_f, mu_t)`` of every tied atom at ``x`` (the class docstring)."""
        return self._atoms(_parameters("x", x, self.diffuse))

    def _atoms(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x = x[: x.size - 2 * self.diffuse]
        ue = np.array([x[0], x[1], self.height])
        vel = self.velocity if x.size == 3 else x[3] * self.heading
        src = self.R @ ue + self.t - self.origin
        r = np.linalg.norm(src, axis=1)
        q = src @ self.frame
        theta = np.column_stack([q[:, :2] / r[:, None], 1.0 / r])
        mu_f = -2 * np.pi * self.srs.tone_spacing * (r + x[2]) / C
        range_rate = np.einsum("li,li->l", src, self.R @ vel) / r
        mu_t = -2 * np.pi * self.srs.symbol_period * self.srs.fc * range_rate / C
        return theta, mu_f, mu_t

    def cost(self, x) -> float:
        """The concentrated cost ``||H - model||^2`` at ``x``."""
        return float(self._solve(_parameters("x", x, self.diffuse))[-1])

    def _solve(self, x: np.ndarray) -> tuple:
        """The model's factors at ``x`` and its gains concentrated out: ``(a, F, T, Fd, Td, c, u,
        cost)``, ``a`` (M, L) the tied atoms' masked steering vectors, ``F``/``T`` their tone and
        symbol vectors, ``Fd``/``Td`` the diffuse atoms', ``c`` (L,) the tied gains, ``u`` (M, D)
        the diffuse atoms' gains per element."""
        theta, mu_f, mu_t = self._atoms(x)
        a = np.exp(1j * spatial_phase_unchecked(theta, self.pos, self.k0)[0]) * self.mask
        F = np.exp(1j * self.s * mu_f[None, :])
        T = np.exp(1j * self.kk * mu_t[None, :])
        D, L, M = self.diffuse, a.shape[1], self.M
        G_tied = (a.conj().T @ a) * (F.conj().T @ F) * (T.conj().T @ T)
        b_tied = np.einsum("ml,ml->l", a.conj(), self._contract(T, F))
        if not D:
            c, cost = self._gains(G_tied, b_tied)
            return a, F, T, F[:, :0], T[:, :0], c, np.zeros((M, 0), complex), cost
        nu = x[x.size - 2 * D :].reshape(D, 2)
        Fd = np.exp(1j * self.s * nu[None, :, 0])
        Td = np.exp(1j * self.kk * nu[None, :, 1])
        # the Gram of the L tied atoms and the D x M diffuse ones (atom j on element m: j M + m)
        g = (F.conj().T @ Fd) * (T.conj().T @ Td)  # (L, D)
        G = np.empty((L + D * M, L + D * M), complex)
        G[:L, :L] = G_tied
        G[:L, L:] = (a.conj().T[:, None, :] * g[:, :, None]).reshape(L, D * M)
        G[L:, :L] = G[:L, L:].conj().T
        G[L:, L:] = np.kron((Fd.conj().T @ Fd) * (Td.conj().T @ Td), np.eye(M))
        b = np.concatenate([b_tied, self._contract(Td, Fd).T.ravel()])
        gains, cost = self._gains(G, b)
        return a, F, T, Fd, Td, gains[:L], gains[L:].reshape(D, M).T, cost

    def model(self, x) -> np.ndarray:
        """The fitted model tensor (M, Nf, Nt) at ``x``, its gains concentrated out."""
        a, F, T, Fd, Td, c, u, _ = self._solve(_parameters("x", x, self.diffuse))
        return np.einsum("ml,sl,kl->msk", a * c, F, T, optimize=True) + np.einsum(
            "mj,sj,kj->msk", u, Fd, Td, optimize=True
        )

    def residual(self, x) -> np.ndarray:
        """``H - model`` at ``x``, the gains concentrated out (variable projection), as real and
        imaginary parts (2 M Nf Nt,): what :func:`scipy.optimize.least_squares` takes."""
        r = (self.H - self.model(x)).ravel()
        return np.concatenate([r.real, r.imag])

    def fit_tied(self, x0, *, max_evaluations: int = 400) -> dict:
        """Levenberg-Marquardt (:func:`scipy.optimize.least_squares`) from ``x0`` (the class
        docstring's parameters): ``x``, ``residual`` (cost over ``||H||^2``), ``evaluations``,
        ``converged`` (its tolerances met, not the evaluation cap)."""
        x0 = _parameters("x0", x0, self.diffuse)
        n = integer("max_evaluations", max_evaluations, minimum=1, maximum=100_000)
        res = least_squares(self.residual, x0, method="lm", max_nfev=n)
        return {"x": res.x, "residual": float(2.0 * res.cost / self.h2),
                "evaluations": int(res.nfev), "converged": bool(res.status > 0)}  # fmt: skip

    def with_diffuse(self, diffuse: int) -> DirectProblem:
        """This problem (the same tensor, masks and maps) with ``diffuse`` diffuse atoms."""
        out = copy.copy(self)
        out.diffuse = integer("diffuse", diffuse, minimum=0, maximum=MAX_DIFFUSE)
        return out


def diffuse_start(H) -> tuple[float, float]:
    """``(mu_f, mu_t)`` [rad] where a tensor ``H`` (M, Nf, Nt) (a fit's residual) has the most
    power summed over the elements: the peak of its delay-Doppler map on the grid of
    :data:`TONE_PAD` ``Nf`` by ``max(MIN_SYMBOL_BINS, Nt)`` points (zero-padded FFTs), where
    :func:`direct_fix` starts a diffuse atom. An all-zero ``H`` is refused (no peak)."""
    return _diffuse_start(check_tensor(H))


def _diffuse_start(H: np.ndarray) -> tuple[float, float]:
    """:func:`diffuse_start` of a checked tensor (the map summed over blocks of elements)."""
    nf, nt = H.shape[1] * TONE_PAD, max(MIN_SYMBOL_BINS, H.shape[2])
    P = np.zeros((nf, nt))
    for i in range(0, H.shape[0], 16):
        P += np.sum(np.abs(np.fft.fft2(H[i : i + 16], s=(nf, nt), axes=(1, 2))) ** 2, axis=0)
    i, j = np.unravel_index(int(np.argmax(P)), P.shape)
    return (float(np.angle(np.exp(2j * np.pi * i / nf))),
            float(np.angle(np.exp(2j * np.pi * j / nt))))  # fmt: skip


def diffuse_threshold(M: int, nf: int, nt: int) -> float:
    """The cost drop, in units of the noise power, that admits one more diffuse atom on an
    (M, Nf, Nt) tensor. Under white noise alone an atom at a given delay and Doppler takes
    ``N0 / 2`` times a chi-square of 2 M degrees of freedom from the cost (its M free gains;
    tested); the start searches the grid of :func:`diffuse_start` and the fit then moves it, so
    the nominal false alarm :data:`DIFFUSE_FALSE_ALARM` is shared over that grid's points
    (Bonferroni). Counting the ``Nf Nt`` resolution cells alone let through 7 to 18 times the
    nominal rate on pure noise; over the grid the rate measured lies below it (tested)."""
    M = integer("M", M, minimum=2, maximum=MAX_TENSOR_SIDE)
    nf = integer("nf", nf, minimum=2, maximum=MAX_TENSOR_SIDE)
    nt = integer("nt", nt, minimum=2, maximum=MAX_TENSOR_SIDE)
    cells = TONE_PAD * nf * max(MIN_SYMBOL_BINS, nt)
    return 0.5 * float(chi2.isf(DIFFUSE_FALSE_ALARM / cells, 2 * M))


@dataclass(frozen=True)
class DirectFix:
    """A fit of :func:`direct_fix`: the UE ``position`` (3,) [m] (the height the prediction's),
    the clock bias ``clock_bias`` [m], the UE's ``speed`` [m/s] along the given velocity (NaN
    when not fitted), the relative residual ``residual`` (cost over ``||H||^2``), the cost's
    ``evaluations``, ``ok``: converged and within the gate of the prediction, and ``diffuse``
    the number of diffuse atoms the fit admitted."""

    position: np.ndarray
    clock_bias: float
    speed: float
    residual: float
    evaluations: int
    ok: bool
    diffuse: int = 0

    def __post_init__(self) -> None:
        record(self, shapes={"position": (3,)}, nonnegative=("residual",), positive=("evaluations",),
               allow_nan=("speed",))  # fmt: skip
        finite_array("position", self.position, shape=(3,))
        if self.residual > 1.0 + 1e-9:
            raise ValueError(f"residual: a share of ||H||^2, at most 1, got {self.residual:g}")
        if np.isfinite(self.speed):
            speeds("speed", self.speed)
        integer("diffuse", self.diffuse, minimum=0, maximum=MAX_DIFFUSE)


def beyond_noise_unchecked(residual: float, noise_power: float, n: int, h2: float) -> float:
    """What a fit's relative ``residual`` (its cost over ``h2``, the tensor's ``||H||^2``) leaves
    beyond the noise of ``n`` samples of power ``noise_power``: ``residual - noise_power n /
    h2``, the unmodelled share (checked by its callers: :func:`direct_fix`,
    :func:`~tunnelkit.design.traceddirect.unmodelled_share`)."""
    return residual - noise_power * n / h2


def diffuse_share(diffuse_above, diffuse: int) -> float:
    """The checked ``diffuse_above`` of :func:`direct_fix`: a share of the tensor's power in
    [0, 1), not above zero without ``diffuse`` atoms (0 to :data:`MAX_DIFFUSE`) to try."""
    n = integer("diffuse", diffuse, minimum=0, maximum=MAX_DIFFUSE)
    above = float(finite_array("diffuse_above", diffuse_above, ndim=0))
    if not 0.0 <= above < 1.0:
        raise ValueError(f"diffuse_above: a share of the tensor's power in [0, 1), got {above:g}")
    if above and not n:
        raise ValueError("diffuse_above: given without diffuse atoms to try")
    return above


def direct_fix(
    route,
    array,
    H,
    prediction,
    velocity,
    *,
    second_order: int = 64,
    speed: bool = True,
    gate: float = 5.0,
    element_second_order: bool = False,
    diffuse: int = 0,
    noise_power: float | None = None,
    diffuse_above: float = 0.0,
) -> DirectFix:
    """The direct fit (module docstring) of the tensor ``H`` (M, Nf, Nt) received at ``array``
    on ``route``'s tunnel from the UE's ``prediction`` (3,) [m] moving at ``velocity`` (3,) [m/s]
    (the V2X message's): the visibility model there (:func:`~.visibility.predicted_model`, at most
    ``second_order`` second-order atoms: every one the image method traces by default), the clock
    bias on a grid of :data:`B_STEP` over the route's support, then ``(x, y, b)`` and, with
    ``speed`` (and a velocity that is not zero), ``(x, y, b, speed)`` by Levenberg-Marquardt;
    flagged beyond ``gate`` [m] from the prediction or unconverged. ``element_second_order``: the
    second-order atoms each on the elements that see it, whether the reference element does or
    not (:func:`~.visibility.visible_second_order`), instead of every element on the paths the
    reference element sees. ``diffuse``: at most that many diffuse atoms (class
    :class:`DirectProblem`), added one at a time, each started at the peak of the last fit's
    residual (:func:`diffuse_start`) and refitted with everything else, and kept while its cost
    drop passes :func:`diffuse_threshold` against ``noise_power`` (the tensor's noise power per
    sample, required with ``diffuse``, at most twice the tensor's mean power per sample, which
    holds the noise). An added atom's fit that does not converge is dropped, never returned: the
    search stops and the fix is the last converged model's. Near the delay of a tied atom a
    diffuse atom's free gains take part of that atom's information (the position's bound grows
    1.2-4.2 times for an atom 0-3 m past the line of sight on the paper's 10 x 10 tensor, not at
    all for one 20 m past: ``benchmarks/bench_direct_diffuse_info.py``), which the told sigmas of
    :mod:`tunnelkit.design.traceddirect` do not know. ``diffuse_above``: the atoms are tried only where the tied
    fit leaves more than this share of the tensor's power beyond the noise (its unmodelled share,
    ``residual - noise_power M Nf Nt / ||H||^2``, in [0, 1)); 0 tries them at every fit."""
    if not hasattr(route, "tunnel") or not hasattr(route, "config"):
        raise TypeError(f"route: expected a SignalRoute, got {type(route).__name__}")
    p0 = route.tunnel.require_inside(
        "prediction", finite_array("prediction", prediction, shape=(3,))
    )
    velocity = speeds("velocity", finite_array("velocity", velocity, shape=(3,)))
    gate = positive("gate", gate)
    if gate > MAX_GATE_M:
        raise ValueError(f"gate: at most {MAX_GATE_M:g} m (a tunnel's length), got {gate:g}")
    n2 = integer("second_order", second_order, minimum=0, maximum=64)
    speed = boolean("speed", speed)
    by_element = boolean("element_second_order", element_second_order)
    n_diffuse = integer("diffuse", diffuse, minimum=0, maximum=MAX_DIFFUSE)
    if n_diffuse and noise_power is None:
        raise ValueError("noise_power: required with diffuse atoms (their test's noise power)")
    n0 = None if noise_power is None else positive("noise_power", noise_power)
    above = diffuse_share(diffuse_above, n_diffuse)
    cfg = route.config
    paths, masks, _ = predicted_model(  # checks array, velocity
        route, array, p0, velocity, n2, element_second_order=by_element
    )
    prob = DirectProblem(H, array, cfg, masks, image_maps(route.tunnel, paths), p0[2], velocity)
    if n0 is not None and n0 > 2.0 * prob.h2 / prob.N:
        raise ValueError(
            f"noise_power: {n0:g} is more than twice the tensor's mean power per sample "
            f"({prob.h2 / prob.N:g}), which holds the noise"
        )
    span = C * cfg.clock_bias_limit + 1.0
    grid = np.arange(-span, span + B_STEP, B_STEP)
    b0 = grid[int(np.argmin([prob.cost(np.r_[p0[:2], b]) for b in grid]))]
    f = prob.fit_tied(np.r_[p0[:2], b0])
    evaluations, ok = f["evaluations"], f["converged"]
    if speed and ok and np.any(prob.heading):  # a speed along no heading cannot be fitted
        f = prob.fit_tied(np.r_[f["x"], np.linalg.norm(prob.velocity)])
        evaluations, ok = evaluations + f["evaluations"], f["converged"]
    used = 0
    if n_diffuse and ok and beyond_noise_unchecked(f["residual"], n0, prob.N, prob.h2) > above:
        threshold = n0 * diffuse_threshold(*prob.H.shape)
        while used < n_diffuse:
            more = prob.with_diffuse(used + 1)
            start = _diffuse_start(prob.H - prob.with_diffuse(used).model(f["x"]))
            x0 = np.r_[f["x"], start]
            g = more.fit_tied(x0, max_evaluations=100 * (x0.size + 1))
            evaluations += g["evaluations"]
            # an unconverged fit is never returned: the last converged model stands
            if not g["converged"] or (f["residual"] - g["residual"]) * prob.h2 < threshold:
                break
            f, used = g, used + 1
    x = f["x"][: f["x"].size - 2 * used]
    moved = float(np.hypot(*(x[:2] - p0[:2])))
    return DirectFix(
        np.array([x[0], x[1], p0[2]]),
        float(x[2]),
        float(x[3]) if x.size == 4 else float("nan"),
        f["residual"],
        evaluations,
        ok and moved <= gate,
        used,
    )
