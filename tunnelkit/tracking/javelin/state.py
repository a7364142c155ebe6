"""The variable-dimension JAVELIN state (Italiano et al. 2026, eq. 43).

``s = [x_u, y_u, z_u, y_v1, z_v1, ..., y_v(L-1), z_v(L-1)]`` with ``D = 2 L_hat + 1``: the UE
position and, per tracked virtual UE (VUE), its lateral and vertical coordinates (its ``x`` equals
the UE's because the reflecting surfaces run along the tunnel). Track 0 is the UE; tracks 1.. are
VUEs, each with a persistent id, a misses counter (zeta of Algorithm 3) and a ``transient`` flag
for paths from dynamic reflectors (used for one epoch only).

A bias-aware tracker (:class:`~tunnelkit.tracking.javelin.consider.ConsiderNoise`) also keeps ``C``
(D, 4 L_hat): the cross-covariance of the state with every track's normalised measurement bias
``u_i`` (4,: ``phi, psi, kappa, d``; columns ``4 i : 4 i + 4``, :func:`bias_slice`). The biases
are consider parameters: never estimated, their own covariance stays ``I``, so ``C`` is all the
filter has to carry about them.

A tracker told an odometry model with repeating errors (:meth:`~.config.JavelinConfig.told`)
carries its error states right after the UE: ``s = [x_u, y_u, z_u, s, b, r, y_v1, z_v1, ...]``
(:data:`ODOMETRY_STATES`: the speed scale factor, the heading bias and the yaw-rate bias;
``n_odo = 3``, or 0 for the paper's white messages: the paper's state exactly). The VUEs then
start at :func:`first_vue`; the measurement model does not depend on the odometry states
(:mod:`~tunnelkit.tracking.javelin.odometrystates`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._validate import boolean, finite_array, integer, positive, record, sequence, vector

__all__ = [
    "ODOMETRY_STATES",
    "JavelinState",
    "bias_slice",
    "first_vue",
    "track_slice",
]

#: the odometry error states a told tracker carries after the UE, in order (the speed scale
#: factor, the heading bias [rad], the yaw-rate bias [rad/s]; :class:`~tunnelkit.odometry.Odometry`)
ODOMETRY_STATES = ("speed_scale", "heading_bias", "yaw_rate_bias")
#: state indices of the odometry states (:data:`ODOMETRY_STATES`, after the UE)
I_SCALE, I_BIAS, I_RATE = range(3, 3 + len(ODOMETRY_STATES))


def first_vue(n_odo: int = 0) -> int:
    """Index of the first VUE coordinate: after the UE (3) and ``n_odo`` odometry states."""
    if type(n_odo) is not int or n_odo not in (0, len(ODOMETRY_STATES)):
        raise ValueError(f"n_odo: expected 0 or {len(ODOMETRY_STATES)}, got {n_odo!r}")
    return 3 + n_odo


def track_slice(i: int, n_odo: int = 0) -> slice:
    """State indices of track ``i``: ``0:3`` for the UE, ``o + 2(i-1) : o + 2 + 2(i-1)`` for VUE
    i, ``o = first_vue(n_odo)``."""
    if type(i) is not int or i < 0:
        i = integer("i", i, minimum=0)
    o = first_vue(n_odo)
    if i == 0:
        return slice(0, 3)
    return slice(o + 2 * (i - 1), o + 2 + 2 * (i - 1))


def bias_slice(i: int) -> slice:
    """Columns of track ``i``'s normalised bias in the consider cross-covariance ``C``."""
    i = integer("i", i, minimum=0)
    return slice(4 * i, 4 * i + 4)


def vue_positions(x: np.ndarray, n_odo: int = 0) -> np.ndarray:
    """3-D VUE positions ``[x_u, y_v, z_v]`` (n_vue, 3) of a state vector ``x`` (eq. 43)."""
    yz = x[first_vue(n_odo) :].reshape(-1, 2)
    return np.column_stack([np.full(len(yz), x[0]), yz])


@dataclass
class JavelinState:
    """Mean ``x`` (D,), covariance ``P`` (D, D) and per-VUE bookkeeping."""

    x: np.ndarray
    P: np.ndarray
    ids: list[int] = field(default_factory=list)
    misses: list[int] = field(default_factory=list)
    transient: list[bool] = field(default_factory=list)
    ue_misses: int = 0
    next_id: int = 1
    C: np.ndarray | None = None
    n_odo: int = 0

    @classmethod
    def initial(
        cls, position, sigma: float, sigma_height: float | None = None, odometry=None
    ) -> JavelinState:
        """UE only, at ``position`` (3,) with covariance ``sigma^2 I_3`` (``P_0|0`` of sec. 4.2);
        ``sigma_height`` (default ``sigma``) replaces the height's standard deviation.
        ``odometry`` (3,): the prior sigmas of the odometry states (:data:`ODOMETRY_STATES`,
        zero mean, uncorrelated with the start); ``None``: no odometry states."""
        p = vector("position", position, 3)
        s = positive("sigma", sigma)
        sh = s if sigma_height is None else positive("sigma_height", sigma_height)
        if odometry is None:
            return cls(x=p.copy(), P=np.diag([s * s, s * s, sh * sh]))
        so = vector("odometry", odometry, len(ODOMETRY_STATES))
        if np.any(so < 0):
            raise ValueError(f"odometry: expected sigmas >= 0, got {so}")
        x = np.concatenate([p, np.zeros(so.size)])
        return cls(x=x, P=np.diag([s * s, s * s, sh * sh, *(so**2)]), n_odo=so.size)

    def __post_init__(self) -> None:
        record(self, skip=("x", "P", "C"), may_be_empty=("ids", "misses", "transient"),
               nonnegative=("ue_misses", "n_odo"), positive=("next_id",))  # fmt: skip
        self.x = finite_array("x", self.x, ndim=1)
        self.P = finite_array("P", self.P, shape=(self.x.size, self.x.size))
        o = first_vue(self.n_odo)
        if self.x.size < o or (self.x.size - o) % 2:
            raise ValueError(
                f"x: expected {o} + 2 n entries (eq. 43, {self.n_odo} odometry states), "
                f"got {self.x.size}"
            )
        n = self.n_vue
        if self.C is not None:
            self.C = finite_array("C", self.C, shape=(self.x.size, 4 * (n + 1)))
        for name in ("ids", "misses", "transient"):
            if len(getattr(self, name)) != n:
                raise ValueError(
                    f"{name}: expected one entry per VUE ({n}), got {len(getattr(self, name))}"
                )

    @property
    def dim(self) -> int:
        """State dimension D = 3 + n_odo + 2 n_vue."""
        return self.x.size

    @property
    def n_vue(self) -> int:
        """Number of tracked VUEs (L_hat - 1)."""
        return (self.x.size - first_vue(self.n_odo)) // 2

    @property
    def odometry(self) -> slice:
        """State indices of the odometry states (:data:`ODOMETRY_STATES`; empty without)."""
        return slice(3, first_vue(self.n_odo))

    @property
    def n_tracks(self) -> int:
        """Number of tracks including the UE (L_hat)."""
        return self.n_vue + 1

    @property
    def ue(self) -> np.ndarray:
        """UE position (3,)."""
        return self.x[:3].copy()

    def position(self, i: int) -> np.ndarray:
        """3-D position of track ``i`` (the UE for 0; ``[x_u, y_v, z_v]`` for a VUE)."""
        i = integer("i", i, minimum=0, maximum=self.n_vue)
        if i == 0:
            return self.ue
        yz = self.x[track_slice(i, self.n_odo)]
        return np.array([self.x[0], yz[0], yz[1]])

    def positions(self) -> np.ndarray:
        """All track positions, shape (L_hat, 3), UE first."""
        return np.vstack([self.x[:3], vue_positions(self.x, self.n_odo)])

    def copy(self) -> JavelinState:
        """A deep copy."""
        return JavelinState(
            self.x.copy(),
            self.P.copy(),
            list(self.ids),
            list(self.misses),
            list(self.transient),
            self.ue_misses,
            self.next_id,
            None if self.C is None else self.C.copy(),
            self.n_odo,
        )

    def remove(self, tracks) -> list[int]:
        """Marginalise VUE tracks (indices >= 1) out of ``x`` and ``P``; returns their ids.

        Marginalising a Gaussian is dropping rows and columns (section 3.5); the UE cannot be
        removed.
        """
        tracks = sorted(
            {integer("tracks", i, minimum=1) for i in sequence("tracks", tracks, empty=True)}
        )
        if not tracks:
            return []
        if tracks[0] < 1 or tracks[-1] > self.n_vue:
            raise ValueError(f"tracks: VUE indices must lie in 1..{self.n_vue}, got {tracks}")
        drop = np.concatenate([np.arange(self.dim)[track_slice(i, self.n_odo)] for i in tracks])
        keep = np.setdiff1d(np.arange(self.dim), drop)
        gone = [self.ids[i - 1] for i in tracks]
        self.x = self.x[keep]
        self.P = self.P[np.ix_(keep, keep)]
        if self.C is not None:
            cols = np.setdiff1d(
                np.arange(self.C.shape[1]),
                np.concatenate([np.arange(self.C.shape[1])[bias_slice(i)] for i in tracks]),
            )
            self.C = self.C[np.ix_(keep, cols)]
        for name in ("ids", "misses", "transient"):
            lst = getattr(self, name)
            setattr(self, name, [v for k, v in enumerate(lst) if k + 1 not in tracks])
        return gone

    def append(self, yz, cov, *, transient: bool = False, cross=None, bias_cross=None) -> int:
        """Append a VUE at ``yz`` (2,) with covariance ``cov`` (2, 2) and cross-covariance
        ``cross`` (2, D) with the current state (default: uncorrelated with the rest); with a
        consider cross-covariance ``C``, the new track's bias (4 columns, uncorrelated with the
        state) and ``bias_cross`` (2, 4 L_hat + 4): the new VUE's cross-covariance with every
        track's bias, its own last (default zero).

        Returns the new track's id; its index is the new ``n_vue``.
        """
        yz = vector("yz", yz, 2)
        cov = finite_array("cov", cov, shape=(2, 2))
        boolean("transient", transient)
        d = self.dim
        P = np.zeros((d + 2, d + 2))
        P[:d, :d] = self.P
        P[d:, d:] = cov
        if cross is not None:
            cross = finite_array("cross", cross, shape=(2, d))
            P[d:, :d] = cross
            P[:d, d:] = cross.T
        if self.C is not None:
            L = self.C.shape[1]
            C = np.zeros((d + 2, L + 4))
            C[:d, :L] = self.C
            if bias_cross is not None:
                C[d:] = finite_array("bias_cross", bias_cross, shape=(2, L + 4))
            self.C = C
        elif bias_cross is not None:
            raise ValueError("bias_cross: the state carries no consider cross-covariance C")
        self.x = np.concatenate([self.x, yz])
        self.P = P
        tid = self.next_id
        self.next_id += 1
        self.ids.append(tid)
        self.misses.append(0)
        self.transient.append(bool(transient))
        return tid
