"""A geometric measurement source for the unit tests (not the signal route).

It evaluates the JAVELIN model exactly (eq. 45-52) from the true UE and its true virtual UEs in a
set of planar reflectors, then adds Gaussian noise drawn from an explicit ``rng``. The workbook's
results come from the signal route instead (channel tensor -> ``extraction.extract_paths``); this
source exists so the tracker's roles can be tested where the answer is known.
"""

from __future__ import annotations

import numpy as np

from tunnelkit._checks import items, sign
from tunnelkit._physical import speeds, step_seconds
from tunnelkit._validate import (
    boolean,
    finite_array,
    integer,
    nonnegative,
    positive,
    probability,
    real,
    rng_or_error,
    vector,
)
from tunnelkit.budget import check_elements
from tunnelkit.geometry import Plane
from tunnelkit.reflection import reflector_point
from tunnelkit.tracking.javelin import PathMeasurements

__all__ = ["GeometricTruth", "geometric_paths", "geometric_stream", "toy_drive", "toy_reflectors"]


def toy_reflectors(half_width: float = 4.5) -> list[Plane]:
    """Two side walls (``y = +-half_width``) and two road-marking plates at the wall/sidewalk
    junction tilted by 55 deg (a toy version of the paper's section 4.1 tunnel)."""
    w = positive("half_width", half_width)
    a = np.radians(55.0)
    return [
        Plane(np.array([0.0, -1.0, 0.0]), w, name="left wall"),
        Plane(np.array([0.0, 1.0, 0.0]), w, name="right wall"),
        Plane(
            np.array([0.0, -np.sin(a), np.cos(a)]),
            -(np.array([0.0, -np.sin(a), np.cos(a)]) @ [0, w - 0.5, 0.2]),
            name="left RRM",
        ),
        Plane(
            np.array([0.0, np.sin(a), np.cos(a)]),
            -(np.array([0.0, np.sin(a), np.cos(a)]) @ [0, -w + 0.5, 0.2]),
            name="right RRM",
        ),
    ]


class GeometricTruth(dict):
    """True per-path values (``vue`` (n, 3), ``reflector`` (n, 3), ``phi``, ``psi``, ``kappa``,
    ``d``, ``v``, ``order``: the path permutation applied)."""


def geometric_paths(
    p_u,
    v_u,
    planes: list[Plane],
    rng: np.random.Generator,
    *,
    bs=(0.0, 0.0, 0.0),
    sigma_phi: float = 0.0,
    sigma_psi: float = 0.0,
    sigma_kappa: float = 0.0,
    sigma_d: float = 0.0,
    sigma_v: float = 0.0,
    clock_bias: float = 0.0,
    los: bool = True,
    shuffle: bool = True,
    doppler_sign: float = -1.0,
) -> tuple[PathMeasurements, GeometricTruth]:
    """Noisy path parameters of the LoS path (if ``los``) and one reflection per plane.

    Exact model: angles of ``p_v - b`` (eq. 46-47, 49-50), ``kappa = ||p_r - b||`` with ``p_r``
    from eq. 45, ``d = ||p_v - b|| + clock_bias`` (eq. 52 before differencing) and
    ``v = doppler_sign * d||p_v - b||/dt`` with the VUE velocity mirrored in its plane.
    A plane with the UE or base station behind it gives no path.
    """
    rng = rng_or_error("rng", rng)
    pu = vector("p_u", p_u, 3)
    vu = vector("v_u", v_u, 3)
    b = vector("bs", bs, 3)
    finite_array("clock_bias", clock_bias, ndim=0)
    items("planes", planes, Plane, empty=True)
    boolean("los", los), boolean("shuffle", shuffle), sign("doppler_sign", doppler_sign)
    for name, s in (
        ("sigma_phi", sigma_phi),
        ("sigma_psi", sigma_psi),
        ("sigma_kappa", sigma_kappa),
        ("sigma_d", sigma_d),
        ("sigma_v", sigma_v),
    ):
        nonnegative(name, s)
    vues, vels, refl = [], [], []
    if los:
        vues.append(pu)
        vels.append(vu)
        refl.append(pu)
    for pl in planes:
        if pl.signed_distance(pu) * pl.signed_distance(b) <= 0:
            continue
        pv = pl.mirror(pu)
        vues.append(pv)
        vels.append(vu - 2.0 * (pl.normal @ vu) * pl.normal)
        refl.append(reflector_point(pu, pv, b))
    vues, vels, refl = (
        np.array(vues).reshape(-1, 3),
        np.array(vels).reshape(-1, 3),
        np.array(refl).reshape(-1, 3),
    )
    q = vues - b
    rng_ = np.linalg.norm(q, axis=1)
    phi = np.arctan2(q[:, 1], q[:, 0])
    psi = np.arctan2(q[:, 2], np.hypot(q[:, 0], q[:, 1]))
    kappa = np.linalg.norm(refl - b, axis=1)
    d = rng_ + clock_bias
    v = doppler_sign * np.sum(q * vels, axis=1) / rng_
    n = len(vues)
    order = rng.permutation(n) if shuffle else np.arange(n)
    noisy = [
        phi + sigma_phi * rng.standard_normal(n),
        psi + sigma_psi * rng.standard_normal(n),
        kappa + sigma_kappa * rng.standard_normal(n),
        d + sigma_d * rng.standard_normal(n),
        v + sigma_v * rng.standard_normal(n),
    ]
    meas = PathMeasurements.from_arrays(*(a[order] for a in noisy))
    truth = GeometricTruth(
        vue=vues[order],
        reflector=refl[order],
        phi=phi[order],
        psi=psi[order],
        kappa=kappa[order],
        d=d[order],
        v=v[order],
        order=order,
    )
    return meas, truth


def toy_drive(
    n: int,
    dt: float,
    *,
    start: float = -45.0,
    stop: float = -8.0,
    speed: float = 10.0,
    lane: float = 1.5,
    amplitude: float = 0.0,
    period: float = 6.0,
    height: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """True positions and velocities (n, 3) of a test drive shuttling smoothly between ``start``
    and ``stop`` along x (peak speed ``speed``, a cosine in time so it turns round without a jump)
    with a lateral sine of ``amplitude`` around ``lane`` (``amplitude = 0``: straight lane)."""
    n = integer("n", n, minimum=1)
    dt = step_seconds("dt", positive("dt", dt))
    for name, value in (("start", start), ("stop", stop), ("lane", lane)):
        real(name, value)
    if stop == start:
        raise ValueError(f"stop: must differ from start ({start}), got {stop}")
    (
        speeds("speed", positive("speed", speed)),
        nonnegative("amplitude", amplitude),
        positive("period", period),
    )
    positive("height", height)
    check_elements("n", 6 * n)
    t = np.arange(n) * dt
    mid, half = 0.5 * (start + stop), 0.5 * abs(stop - start)
    wx = speed / half
    x = mid - half * np.cos(wx * t)
    vx = half * wx * np.sin(wx * t)
    w = 2.0 * np.pi / period
    y = lane + amplitude * np.sin(w * t)
    vy = amplitude * w * np.cos(w * t)
    P = np.column_stack([x, y, np.full(t.size, height)])
    V = np.column_stack([vx, vy, np.zeros(t.size)])
    return P, V


def geometric_stream(
    P, V, planes: list[Plane], rng: np.random.Generator, *, los_probability: float = 1.0, **kw
) -> list[PathMeasurements]:
    """:func:`geometric_paths` for every epoch of a drive; LoS present with ``los_probability``.

    Extra keywords (noise sigmas, ``bs``, ``clock_bias`` as a callable ``rng -> float`` or a
    number) go to :func:`geometric_paths`.
    """
    rng = rng_or_error("rng", rng)
    P = finite_array("P", P, shape=(None, 3))
    V = finite_array("V", V, shape=(len(P), 3))
    items("planes", planes, Plane, empty=True)
    probability("los_probability", los_probability, open_interval=False)
    bias = kw.pop("clock_bias", 0.0)
    out = []
    for p, v in zip(np.asarray(P, float), np.asarray(V, float)):
        los = bool(rng.random() < los_probability)
        b = bias(rng) if callable(bias) else bias
        out.append(geometric_paths(p, v, planes, rng, los=los, clock_bias=b, **kw)[0])
    return out
