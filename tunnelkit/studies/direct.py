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
ring around the prediction, was tried and did not remove it (``docs/results/traced-models.md``). Used under the tracker by :mod:`.direct_track`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .._physical import speeds
from .._validate import boolean, finite_array, instance, integer, positive, record, sequence
from ..arrays import ArrayGeometry
from ..channel import SRSConfig
from ..constants import C
from ..extraction.numerics import spatial_phase_unchecked
from ..propagation import SECOND_ORDER, Path, Tunnel3D
from .visibility import MaskedProblem, predicted_model

__all__ = ["DirectFix", "DirectProblem", "direct_fix", "image_maps"]

#: [m] the largest UE height above the road and the largest gate :func:`direct_fix` takes
MAX_HEIGHT_M, MAX_GATE_M = 20.0, 1000.0
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


def _parameters(name: str, x) -> np.ndarray:
    """``x`` checked as ``(x, y, b)`` [m] or ``(x, y, b, speed)`` [m, m/s]."""
    x = finite_array(name, x, ndim=1)
    if x.size not in (3, 4):
        raise ValueError(f"{name}: expected (x, y, b) or (x, y, b, speed), got {x.size} values")
    if x.size == 4:
        speeds(name, x[3])
    return x


class DirectProblem(MaskedProblem):
    """The tensor ``H`` at ``array`` (an :class:`~tunnelkit.arrays.ArrayGeometry`) with the radio
    ``srs``: eq. 1 with ``mask`` (M, L) (:func:`~.visibility.visible_paths`), atom ``l``'s wave
    origin ``R[l] @ ue + t[l]`` (:func:`image_maps`) for the UE at ``(x, y, height)`` moving at
    ``velocity`` (3,), its delay its length plus the clock bias ``b`` [m] (module docstring). The
    parameters ``x``: ``(x, y, b)`` [m], or ``(x, y, b, speed)`` with the UE moving at ``speed``
    [m/s] along ``velocity``'s direction."""

    def __init__(self, H, array, srs, mask, maps, height: float, velocity):
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
        speed = float(np.linalg.norm(self.velocity))
        self.heading = self.velocity / speed if speed > 0 else np.zeros(3)
        self.origin, self.frame = array.origin, array.R
        self._beta = np.zeros((L, 0))

    def atoms(self, x) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """eq. 1's ``(theta, mu_f, mu_t)`` of every atom at ``x`` (the class docstring)."""
        return self._atoms(_parameters("x", x))

    def _atoms(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
        return float(self._evaluate(*self.atoms(x), self._beta, derivatives=False)["cost"])

    def residual(self, x) -> np.ndarray:
        """``H - model`` at ``x``, the gains concentrated out (variable projection), as real and
        imaginary parts (2 M Nf Nt,): what :func:`scipy.optimize.least_squares` takes."""
        theta, mu_f, mu_t = self._atoms(_parameters("x", x))
        c = self._evaluate(theta, mu_f, mu_t, self._beta, derivatives=False)["c"]
        a = np.exp(1j * spatial_phase_unchecked(theta, self.pos, self.k0)[0]) * self.mask * c
        F = np.exp(1j * self.s * mu_f[None, :])
        T = np.exp(1j * self.kk * mu_t[None, :])
        r = (self.H - np.einsum("ml,sl,kl->msk", a, F, T, optimize=True)).ravel()
        return np.concatenate([r.real, r.imag])

    def fit_tied(self, x0, *, max_evaluations: int = 400) -> dict:
        """Levenberg-Marquardt (:func:`scipy.optimize.least_squares`) from ``x0`` (3 or 4
        values, the class docstring): ``x``, ``residual`` (cost over ``||H||^2``),
        ``evaluations``, ``converged`` (its tolerances met, not the evaluation cap)."""
        x0 = _parameters("x0", x0)
        n = integer("max_evaluations", max_evaluations, minimum=1, maximum=100_000)
        res = least_squares(self.residual, x0, method="lm", max_nfev=n)
        return {"x": res.x, "residual": float(2.0 * res.cost / self.h2),
                "evaluations": int(res.nfev), "converged": bool(res.status > 0)}  # fmt: skip


@dataclass(frozen=True)
class DirectFix:
    """A fit of :func:`direct_fix`: the UE ``position`` (3,) [m] (the height the prediction's),
    the clock bias ``clock_bias`` [m], the UE's ``speed`` [m/s] along the given velocity (NaN
    when not fitted), the relative residual ``residual`` (cost over ``||H||^2``), the cost's
    ``evaluations`` and ``ok``: converged and within the gate of the prediction."""

    position: np.ndarray
    clock_bias: float
    speed: float
    residual: float
    evaluations: int
    ok: bool

    def __post_init__(self) -> None:
        record(self, shapes={"position": (3,)}, nonnegative=("residual",), positive=("evaluations",),
               allow_nan=("speed",))  # fmt: skip
        finite_array("position", self.position, shape=(3,))
        if self.residual > 1.0 + 1e-9:
            raise ValueError(f"residual: a share of ||H||^2, at most 1, got {self.residual:g}")
        if np.isfinite(self.speed):
            speeds("speed", self.speed)


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
    reference element sees."""
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
    cfg = route.config
    paths, masks, _ = predicted_model(  # checks array, velocity
        route, array, p0, velocity, n2, element_second_order=by_element
    )
    prob = DirectProblem(H, array, cfg, masks, image_maps(route.tunnel, paths), p0[2], velocity)
    span = C * cfg.clock_bias_limit + 1.0
    grid = np.arange(-span, span + B_STEP, B_STEP)
    b0 = grid[int(np.argmin([prob.cost(np.r_[p0[:2], b]) for b in grid]))]
    f = prob.fit_tied(np.r_[p0[:2], b0])
    evaluations, ok = f["evaluations"], f["converged"]
    if speed and ok and np.any(prob.heading):  # a speed along no heading cannot be fitted
        f = prob.fit_tied(np.r_[f["x"], np.linalg.norm(prob.velocity)])
        evaluations, ok = evaluations + f["evaluations"], f["converged"]
    x = f["x"]
    moved = float(np.hypot(*(x[:2] - p0[:2])))
    return DirectFix(
        np.array([x[0], x[1], p0[2]]),
        float(x[2]),
        float(x[3]) if x.size == 4 else float("nan"),
        f["residual"],
        evaluations,
        ok and moved <= gate,
    )
