"""Table of bad inputs for the probe in ``test_bad_input_probe.py``.

Every case is one call of a public callable (or one command line) with exactly one bad argument,
and the parameter name(s) a clear error must mention. Nothing here is a valid input: any return
value counts as a silent wrong number. Size cases ask for more memory or time than any budget
allows; they run in a forked child with an address-space limit and a timeout.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

NAN, INF = float("nan"), float("inf")


@dataclass(frozen=True)
class Case:
    id: str
    call: Callable[[], object]
    names: tuple[str, ...]
    heavy: bool = False  # may hang or exhaust memory before the fix


@dataclass(frozen=True)
class CliCase:
    id: str
    argv: tuple[str, ...]
    names: tuple[str, ...]


# bad values for a real scalar and for an array of reals
SCALAR_BAD = {
    "nan": NAN,
    "inf": INF,
    "-inf": -INF,
    "str": "1.0",
    "bool": True,
    "complex": 1.0 + 1.0j,
    "none": None,
}
ARRAY_BAD = {"nan": "nan", "inf": "inf", "complex": "complex", "str": "str", "none": None}


def _bad_array(good, kind):
    """``good`` with one entry made NaN/inf/complex, or replaced by strings/None."""
    if kind is None:
        return None
    a = np.array(good, dtype=float)
    if kind == "str":
        return np.full(a.shape, "x").tolist()
    if kind == "complex":
        out = a.astype(complex)
        out.flat[0] += 1j
        return out
    a.flat[0] = NAN if kind == "nan" else INF
    return a


def _tk():
    import tunnelkit as tk

    return tk


def _mod(path):
    import importlib

    return importlib.import_module(f"tunnelkit.{path}")


def _scalar_cases(cases, label, fn, good: dict, params, kinds=SCALAR_BAD):
    for p in params:
        for kname, bad in kinds.items():
            kw = {**good, p: bad}

            def call(fn=fn, kw=kw):
                return fn()(**kw)

            cases.append(Case(f"{label}[{p}={kname}]", call, (p,)))


def _array_cases(cases, label, fn, good: dict, params, names=None):
    for p in params:
        for kname, kind in ARRAY_BAD.items():

            def call(fn=fn, good=good, p=p, kind=kind):
                return fn()(**{**good, p: _bad_array(good[p], kind)})

            cases.append(Case(f"{label}[{p}={kname}]", call, names or (p,)))


def _setup():
    d = _mod("tracking.doppler")
    return d.DopplerSetup(tx=np.array([0.0, 4.5]), dz=2.5, fc=1.35e9, dt=0.032)


def _vs_model():
    return _mod("tracking.virtual_station").model_from_scenario("jiang2023-straight")


def _tunnel3d():
    return _mod("propagation").semicircular_tunnel()


def _array3d():
    return _mod("arrays").make_array(
        4, 4, fc=5.9e9, azimuth=0.0, elevation=-0.5, origin=[0, 0, 4.8]
    )


def build_cases() -> list[Case]:
    c: list[Case] = []
    st = [[0.0, 0.0], [0.0, 10.0], [0.0, -10.0]]
    p2 = [30.0, 2.0]

    # --- constants ---------------------------------------------------------------------------
    _scalar_cases(c, "wavelength", lambda: _mod("constants").wavelength, {"fc": 5.9e9}, ["fc"])
    c.append(Case("wavelength[fc=-1e9]", lambda: _mod("constants").wavelength(-1e9), ("fc",)))
    for fn in ("db2lin", "dbm2watt", "deg", "rad"):
        for kname in ("nan", "complex", "str"):
            arg = (
                "x_db"
                if fn == "db2lin"
                else {"dbm2watt": "p_dbm", "deg": "x_rad", "rad": "x_deg"}[fn]
            )
            c.append(
                Case(
                    f"{fn}[{kname}]",
                    lambda fn=fn, arg=arg, k=kname: getattr(_mod("constants"), fn)(
                        **{arg: _bad_array([1.0, 2.0], k)}
                    ),
                    (arg,),
                )
            )
    c.append(Case("lin2db[nan]", lambda: _mod("constants").lin2db([1.0, NAN]), ("x",)))
    c.append(Case("lin2db[complex]", lambda: _mod("constants").lin2db([1.0 + 1j]), ("x",)))

    # --- geometry ----------------------------------------------------------------------------
    _array_cases(
        c,
        "Plane",
        lambda: _mod("geometry").Plane,
        {"normal": [1.0, 0.0], "offset": 1.0},
        ["normal"],
    )
    _scalar_cases(
        c,
        "Plane",
        lambda: _mod("geometry").Plane,
        {"normal": [1.0, 0.0], "offset": 1.0},
        ["offset"],
    )
    _scalar_cases(
        c, "line", lambda: _mod("geometry").line, {"A": 1.0, "B": 1.0, "C": 0.0}, ["A", "C"]
    )
    wall = lambda: _mod("geometry").line(0.0, 1.0, -5.0)  # noqa: E731
    c.append(Case("Plane.mirror[p=nan]", lambda: wall().mirror([1.0, NAN]), ("p",)))
    c.append(Case("Plane.mirror[p=complex]", lambda: wall().mirror([1.0, 1j]), ("p",)))
    c.append(
        Case(
            "virtual_stations[base_station=nan]",
            lambda: _mod("tunnel2d").virtual_stations([NAN, 0.0], [wall()]),
            ("base_station",),
        )
    )
    c.append(
        Case(
            "virtual_stations[walls=[]]",
            lambda: _mod("tunnel2d").virtual_stations([0.0, 0.0], []),
            ("walls",),
        )
    )
    c.append(
        Case(
            "specular_point[target=inf]",
            lambda: _mod("reflection").specular_point([0.0, 0.0], [INF, 1.0], wall()),
            ("target",),
        )
    )
    c.append(
        Case(
            "specular_point[target beyond plane]",
            lambda: _mod("reflection").specular_point([0.0, 0.0], [3.0, 9.0], wall()),
            ("target",),
        )
    )
    _array_cases(
        c,
        "reflector_point",
        lambda: _mod("reflection").reflector_point,
        {"p_u": [10.0, 1.0, 1.0], "p_v": [10.0, 9.0, 1.0]},
        ["p_u", "p_v"],
    )
    c.append(
        Case(
            "Tunnel2D.from_lines[nan]",
            lambda: _mod("tunnel2d").Tunnel2D.from_lines((0, 1, -5), (0, 1, NAN)),
            ("line1", "C", "line coefficients (A, B, C)", "offset"),
        )
    )
    c.append(
        Case(
            "Tunnel2D.from_lines[coincide]",
            lambda: _mod("tunnel2d").Tunnel2D.from_lines((0, 1, -5), (0, 1, -5)),
            ("walls",),
        )
    )

    # --- crlb ----------------------------------------------------------------------------------
    for kname in ("nan", "inf", "complex", "str"):
        c.append(
            Case(
                f"wrap_angle[{kname}]",
                lambda k=kname: _mod("crlb").wrap_angle(_bad_array([1.0, 2.0], k)),
                ("a",),
            )
        )
    c.append(Case("wrap_angle[None]", lambda: _mod("crlb").wrap_angle(None), ("a",)))
    _array_cases(
        c, "toa_doa", lambda: _mod("crlb").toa_doa, {"p": p2, "stations": st}, ["p", "stations"]
    )
    _array_cases(
        c,
        "toa_doa_jacobian",
        lambda: _mod("crlb").toa_doa_jacobian,
        {"p": p2, "stations": st},
        ["p", "stations"],
    )
    fim_good = {"p": p2, "stations": st, "sigma_theta": 0.01, "sigma_d": 0.5}
    _scalar_cases(
        c,
        "fim_toa_doa",
        lambda: _mod("crlb").fim_toa_doa,
        fim_good,
        ["sigma_theta", "sigma_d"],
        {k: v for k, v in SCALAR_BAD.items() if k != "none"},
    )
    c.append(
        Case(
            "fim_toa_doa[sigma_d=-1]",
            lambda: _mod("crlb").fim_toa_doa(**{**fim_good, "sigma_d": -1.0}),
            ("sigma_d",),
        )
    )
    c.append(
        Case(
            "fim_toa_doa[form=bogus]",
            lambda: _mod("crlb").fim_toa_doa(**fim_good, form="bogus"),
            ("form",),
        )
    )
    c.append(
        Case(
            "crlb_rmse[sigma_d=nan]",
            lambda: _mod("crlb").crlb_rmse(p2, st, 0.01, NAN),
            ("sigma_d",),
        )
    )
    for label, F in (
        ("-eye", -np.eye(2)),
        ("-eye3", -np.eye(3)),
        ("nonsym", np.array([[2.0, 1.0], [0.0, 2.0]])),
        ("nonsym3", np.array([[2.0, 1.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]])),
        ("indefinite", np.array([[1.0, 2.0], [2.0, 1.0]])),
        ("nan", np.array([[1.0, NAN], [NAN, 1.0]])),
        ("complex", np.eye(2) * (1 + 1j)),
        ("str", [["a", "b"], ["c", "d"]]),
        ("1d", np.ones(2)),
        ("nonsquare", np.ones((2, 3))),
    ):
        c.append(Case(f"crlb_trace[F={label}]", lambda F=F: _mod("crlb").crlb_trace(F), ("F",)))
    h = lambda x: np.stack([x[..., 0], x[..., 1]], -1)  # noqa: E731
    c.append(
        Case(
            "numeric_jacobian[p=nan]", lambda: _mod("crlb").numeric_jacobian(h, [NAN, 1.0]), ("p",)
        )
    )
    c.append(
        Case(
            "numeric_jacobian[step=0]",
            lambda: _mod("crlb").numeric_jacobian(h, [1.0, 1.0], step=0.0),
            ("step",),
        )
    )
    c.append(
        Case(
            "numeric_jacobian[h=str]",
            lambda: _mod("crlb").numeric_jacobian("h", [1.0, 1.0]),
            ("h",),
        )
    )
    c.append(
        Case(
            "numeric_fim[R=-eye]",
            lambda: _mod("crlb").numeric_fim(h, [1.0, 1.0], -np.eye(2)),
            ("R",),
        )
    )
    c.append(
        Case(
            "numeric_fim[R=nonsym]",
            lambda: _mod("crlb").numeric_fim(h, [1.0, 1.0], np.array([[1.0, 0.5], [0.0, 1.0]])),
            ("R",),
        )
    )

    # --- positioning -----------------------------------------------------------------------------
    d_hat = [30.0, 31.0, 32.0]
    th_hat = [0.1, -0.2, 0.3]
    ls_good = {"stations": st, "d_hat": d_hat, "theta_hat": th_hat}
    _array_cases(
        c,
        "ls_toa_doa",
        lambda: _mod("positioning").ls_toa_doa,
        ls_good,
        ["stations", "d_hat", "theta_hat"],
    )
    tsw_good = {**ls_good, "sigma_d": 0.5, "sigma_theta": 0.01}
    _array_cases(
        c, "tswls", lambda: _mod("positioning").tswls, tsw_good, ["stations", "d_hat", "theta_hat"]
    )
    _scalar_cases(
        c,
        "tswls",
        lambda: _mod("positioning").tswls,
        tsw_good,
        ["sigma_d", "sigma_theta"],
        {k: v for k, v in SCALAR_BAD.items() if k != "none"},
    )
    c.append(
        Case(
            "tswls[one station]",
            lambda: _mod("positioning").tswls([[0.0, 0.0]], [30.0], [0.1], 0.5, 0.01),
            ("stations",),
        )
    )
    c.append(
        Case(
            "tswls[coincident stations]",
            lambda: _mod("positioning").tswls(
                [[0.0, 0.0], [0.0, 0.0]], [30.0, 30.0], [0.1, 0.1], 0.5, 0.01
            ),
            ("stations",),
        )
    )
    c.append(
        Case(
            "ls_toa_doa[one station]",
            lambda: _mod("positioning").ls_toa_doa([[0.0, 0.0]], [30.0], [0.1]),
            ("stations",),
        )
    )
    c.append(
        Case(
            "ls_toa_doa[coincident stations]",
            lambda: _mod("positioning").ls_toa_doa(
                [[1.0, 2.0], [1.0, 2.0]], [30.0, 30.0], [0.1, 0.1]
            ),
            ("stations",),
        )
    )
    rng = lambda: np.random.default_rng(0)  # noqa: E731
    c.append(
        Case(
            "simulate_toa_doa[size=2.5]",
            lambda: _mod("positioning").simulate_toa_doa(p2, st, 0.01, 0.5, rng(), size=2.5),
            ("size",),
        )
    )
    c.append(
        Case(
            "simulate_toa_doa[rng=0]",
            lambda: _mod("positioning").simulate_toa_doa(p2, st, 0.01, 0.5, 0),
            ("rng",),
        )
    )
    c.append(
        Case(
            "simulate_toa_doa[size=1e12]",
            lambda: _mod("positioning").simulate_toa_doa(p2, st, 0.01, 0.5, rng(), size=10**12),
            ("size",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "toa_only_candidates[d_hat=nan]",
            lambda: _mod("positioning").toa_only_candidates(st, [NAN, 3.0]),
            ("d_hat",),
        )
    )

    # --- fresnel ----------------------------------------------------------------------------------
    geo = {"R": 3.5, "W": 3.0, "y_u": 2.5, "fc": 5.9e9, "eps_phi": 0.15}
    for fn in ("mmax_2d", "mmax_nonparaxial", "mmax_exact"):
        _scalar_cases(c, fn, lambda fn=fn: getattr(_mod("fresnel"), fn), geo, list(geo))
    for p, v in (("fc", -1e9), ("eps_phi", 0.0), ("R", -1.0), ("W", 0.0), ("y_u", 4.0)):
        c.append(
            Case(
                f"mmax_2d[{p}={v}]", lambda p=p, v=v: _mod("fresnel").mmax_2d(**{**geo, p: v}), (p,)
            )
        )
    c.append(
        Case(
            "mmax_3d[p_v=nan]",
            lambda: _mod("fresnel").mmax_3d([NAN, 1.0, 0.0], 5.9e9, 0.15),
            ("p_v",),
        )
    )
    c.append(
        Case("mmax_3d[fc=0]", lambda: _mod("fresnel").mmax_3d([3.5, 3.5, 0.0], 0.0, 0.15), ("fc",))
    )
    for p, v in (("M", 2.5), ("M", True), ("M", "4"), ("M", 1)):
        c.append(
            Case(
                f"phase_mismatch[{p}={v!r}]",
                lambda v=v: _mod("fresnel").phase_mismatch(v, 3.5, 3.0, 2.5, 5.9e9),
                ("M",),
            )
        )
    c.append(
        Case(
            "phase_mismatch[M=1e9]",
            lambda: _mod("fresnel").phase_mismatch(10**9, 3.5, 3.0, 2.5, 5.9e9),
            ("M",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "phase_mismatch_ura[M=1e5]",
            lambda: _mod("fresnel").phase_mismatch_ura(100000, 3.5, 3.0, 2.5, 5.9e9),
            ("M",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "mmax_exact[m_limit=2.5]",
            lambda: _mod("fresnel").mmax_exact(**geo, m_limit=2.5),
            ("m_limit",),
        )
    )
    c.append(
        Case(
            "mmax_exact_ura[m_limit=1e6]",
            lambda: _mod("fresnel").mmax_exact_ura(3.5, 3.0, 2.5, 5.9e9, 3.0, m_limit=10**6),
            ("m_limit",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "mmax_exact_grid[m_limit=1e12]",
            lambda: _mod("fresnel").mmax_exact_grid(3.5, 3.0, 2.5, 5.9e9, 3.0, m_limit=10**12),
            ("m_limit",),
            heavy=True,
        )
    )
    c.append(Case("aperture[M=nan]", lambda: _mod("fresnel").aperture(NAN, 5.9e9), ("M",)))
    c.append(
        Case(
            "fraunhofer_distance[D=complex]",
            lambda: _mod("fresnel").fraunhofer_distance(1j, 5.9e9),
            ("D",),
        )
    )
    c.append(
        Case("mmax_fraunhofer[R=str]", lambda: _mod("fresnel").mmax_fraunhofer("3", 5.9e9), ("R",))
    )
    c.append(
        Case(
            "ula_positions[M=1e12]",
            lambda: _mod("fresnel").ula_positions(10**12, 5.9e9),
            ("M",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "ura_positions[M=1e6]",
            lambda: _mod("fresnel").ura_positions(10**6, 5.9e9),
            ("M",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "ura_positions[tilt=nan]",
            lambda: _mod("fresnel").ura_positions(4, 5.9e9, tilt=NAN),
            ("tilt",),
        )
    )
    c.append(
        Case(
            "mismatch_profile[positions=complex]",
            lambda: _mod("fresnel").mismatch_profile(np.ones((2, 3)) * 1j, 3.5, 3.0, 2.5, 5.9e9),
            ("positions",),
        )
    )
    c.append(
        Case(
            "aperture_profile[M=1e12]",
            lambda: _mod("fresnel").aperture_profile(10**12, 3.5, 3.0, 2.5, 5.9e9),
            ("M",),
            heavy=True,
        )
    )

    # --- arrays -------------------------------------------------------------------------------------
    for p, v in (
        ("n_rows", 2.5),
        ("n_rows", True),
        ("n_cols", "4"),
        ("n_cols", 0),
        ("spacing", NAN),
        ("spacing", -0.1),
    ):
        c.append(
            Case(
                f"ura[{p}={v!r}]",
                lambda p=p, v=v: _mod("arrays").ura(
                    **{"n_rows": 2, "n_cols": 2, "spacing": 0.1, p: v}
                ),
                (p,),
            )
        )
    c.append(
        Case(
            "ura[n_rows=1e6]",
            lambda: _mod("arrays").ura(10**6, 10**6, 0.1),
            ("n_rows", "n_cols"),
            heavy=True,
        )
    )
    c.append(Case("ula[n=1e12]", lambda: _mod("arrays").ula(10**12, 0.1), ("n",), heavy=True))
    _scalar_cases(
        c,
        "rotation",
        lambda: _mod("arrays").rotation,
        {"azimuth": 0.0, "elevation": 0.0},
        ["azimuth", "elevation"],
    )
    mk = {"n_rows": 4, "n_cols": 4, "fc": 5.9e9, "azimuth": 0.0, "elevation": -0.5}
    _scalar_cases(
        c, "make_array", lambda: _mod("arrays").make_array, mk, ["fc", "azimuth", "elevation"]
    )
    for p, v in (
        ("n_rows", 4.5),
        ("n_cols", False),
        ("origin", [0.0, NAN, 0.0]),
        ("origin", [0, 0]),
        ("spacing", 0.0),
        ("fc", -5.9e9),
    ):
        c.append(
            Case(
                f"make_array[{p}={v!r}]",
                lambda p=p, v=v: _mod("arrays").make_array(**{**mk, p: v}),
                (p,),
            )
        )
    c.append(
        Case(
            "make_array[1e5 x 1e5]",
            lambda: _mod("arrays").make_array(10**5, 10**5, fc=5.9e9, azimuth=0.0, elevation=-0.5),
            ("n_rows", "n_cols"),
            heavy=True,
        )
    )
    c.append(
        Case(
            "check_element_positions[dup]",
            lambda: _mod("arrays").check_element_positions(
                "positions", [[0, 0, 0], [1, 0, 0], [1, 0, 0]]
            ),
            ("positions",),
        )
    )
    c.append(
        Case(
            "check_element_positions[complex]",
            lambda: _mod("arrays").check_element_positions("positions", [[0, 0, 0], [1j, 0, 0]]),
            ("positions",),
        )
    )
    c.append(
        Case("ArrayGeometry.to_local[nan]", lambda: _array3d().to_local([NAN, 0.0, 0.0]), ("p",))
    )

    # --- propagation ------------------------------------------------------------------------------
    c.append(
        Case("fresnel_te[eps_r=nan]", lambda: _mod("propagation").fresnel_te(NAN, 0.5), ("eps_r",))
    )
    c.append(
        Case("fresnel_te[cos_i=5]", lambda: _mod("propagation").fresnel_te(5.24, 5.0), ("cos_i",))
    )
    c.append(
        Case(
            "fresnel_te[cos_i=-0.5]", lambda: _mod("propagation").fresnel_te(5.24, -0.5), ("cos_i",)
        )
    )
    c.append(
        Case("fresnel_te[cos_i=nan]", lambda: _mod("propagation").fresnel_te(5.24, NAN), ("cos_i",))
    )
    c.append(
        Case(
            "fresnel_te[cos_i=complex]",
            lambda: _mod("propagation").fresnel_te(5.24, 0.5j),
            ("cos_i",),
        )
    )
    c.append(
        Case(
            "fresnel_te[cos_i=str]", lambda: _mod("propagation").fresnel_te(5.24, "0.5"), ("cos_i",)
        )
    )
    c.append(
        Case("fresnel_te[eps_r=str]", lambda: _mod("propagation").fresnel_te("5", 0.5), ("eps_r",))
    )
    c.append(
        Case("fresnel_te[eps_r=inf]", lambda: _mod("propagation").fresnel_te(INF, 0.5), ("eps_r",))
    )
    _scalar_cases(
        c,
        "concrete_permittivity",
        lambda: _mod("propagation").concrete_permittivity,
        {"fc": 5.9e9},
        ["fc"],
    )
    semi = {"length": 100.0, "width": 10.0, "height": 5.0}
    _scalar_cases(
        c,
        "semicircular_tunnel",
        lambda: _mod("propagation").semicircular_tunnel,
        semi,
        ["length", "width", "height"],
    )
    for v in (2.5, True, "12", 1):
        c.append(
            Case(
                f"semicircular_tunnel[n_facets={v!r}]",
                lambda v=v: _mod("propagation").semicircular_tunnel(n_facets=v),
                ("n_facets",),
            )
        )
    c.append(
        Case(
            "semicircular_tunnel[x_start=nan]",
            lambda: _mod("propagation").semicircular_tunnel(x_start=NAN),
            ("x_start",),
        )
    )
    c.append(
        Case(
            "semicircular_tunnel[n_facets=1e6]",
            lambda: _mod("propagation").semicircular_tunnel(n_facets=10**6),
            ("n_facets",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "semicircular_tunnel[n_facets=1e12]",
            lambda: _mod("propagation").semicircular_tunnel(n_facets=10**12),
            ("n_facets",),
            heavy=True,
        )
    )
    lane = {"x_start": -40.0, "x_end": 40.0, "speed": 10.0, "period": 0.1, "y": -2.0, "height": 1.5}
    _scalar_cases(
        c, "lane_trajectory", lambda: _mod("propagation").lane_trajectory, lane, list(lane)
    )
    _scalar_cases(
        c,
        "lane_trajectory",
        lambda: _mod("propagation").lane_trajectory,
        lane,
        ["slalom_amplitude", "slalom_wavelength"],
        {k: v for k, v in SCALAR_BAD.items() if k in ("nan", "inf", "str", "complex")},
    )
    c.append(
        Case(
            "lane_trajectory[period=1e-15]",
            lambda: _mod("propagation").lane_trajectory(**{**lane, "period": 1e-15}),
            ("period",),
            heavy=True,
        )
    )
    ue = [10.0, -2.0, 1.5]

    def tp(**kw):
        return _mod("propagation").trace_paths(
            _tunnel3d(), _array3d(), **{"ue": ue, "fc": 5.9e9, **kw}
        )

    c.append(Case("trace_paths[kinds=bogus]", lambda: tp(kinds=("bogus",)), ("kinds",)))
    c.append(Case("trace_paths[kinds=str]", lambda: tp(kinds="los"), ("kinds",)))
    c.append(Case("trace_paths[kinds=empty]", lambda: tp(kinds=()), ("kinds",)))
    c.append(Case("trace_paths[fc=nan]", lambda: tp(fc=NAN), ("fc",)))
    c.append(Case("trace_paths[fc=-1]", lambda: tp(fc=-1.0), ("fc",)))
    c.append(Case("trace_paths[ue=nan]", lambda: tp(ue=[NAN, 0.0, 1.0]), ("ue",)))
    c.append(Case("trace_paths[ue outside]", lambda: tp(ue=[0.0, 50.0, 1.0]), ("ue",)))
    c.append(
        Case(
            "trace_paths[ue_velocity=complex]",
            lambda: tp(ue_velocity=[1j, 0.0, 0.0]),
            ("ue_velocity",),
        )
    )
    c.append(Case("trace_paths[front_only=str]", lambda: tp(front_only="no"), ("front_only",)))
    c.append(
        Case(
            "trace_paths[tunnel=None]",
            lambda: _mod("propagation").trace_paths(None, _array3d(), ue, fc=5.9e9),
            ("tunnel",),
        )
    )
    tb = {"x_center": 0.0, "y_center": 0.0}
    _scalar_cases(
        c, "truck_box", lambda: _mod("propagation").truck_box, tb, ["x_center", "y_center"]
    )
    rm = {"x_range": [0.0, 5.0], "y": 4.0, "z": 0.5, "width": 0.5, "inclination_deg": 55.0}
    _scalar_cases(
        c,
        "road_marking",
        lambda: _mod("propagation").road_marking,
        rm,
        ["y", "z", "inclination_deg"],
        {k: v for k, v in SCALAR_BAD.items() if k in ("nan", "inf", "str", "complex")},
    )
    c.append(Case("Box[lo=nan]", lambda: _mod("propagation").Box([NAN, 0, 0], [1, 1, 1]), ("lo",)))
    c.append(
        Case(
            "Facet.reflection_coefficient[cos_i=2]",
            lambda: _tunnel3d().facets[0].reflection_coefficient(5.9e9, 2.0),
            ("cos_i",),
        )
    )
    c.append(
        Case(
            "select_array[ue=nan]",
            lambda: _mod("propagation").select_array([_array3d()], [NAN, 0, 0]),
            ("ue",),
        )
    )

    # --- metrics --------------------------------------------------------------------------------------
    c.append(Case("rmse[empty]", lambda: _mod("metrics").rmse([], []), ("estimate", "truth")))
    c.append(
        Case(
            "rmse[empty 2d]",
            lambda: _mod("metrics").rmse(np.zeros((0, 2)), np.zeros((0, 2))),
            ("estimate", "truth"),
        )
    )
    c.append(
        Case("rmse[nan]", lambda: _mod("metrics").rmse([[NAN, 0.0]], [[0.0, 0.0]]), ("estimate",))
    )
    c.append(
        Case(
            "rmse[complex]", lambda: _mod("metrics").rmse([[1j, 0.0]], [[0.0, 0.0]]), ("estimate",)
        )
    )
    c.append(
        Case(
            "rmse[shape]",
            lambda: _mod("metrics").rmse(np.zeros((3, 2)), np.zeros((4, 2))),
            ("estimate", "truth"),
        )
    )
    c.append(
        Case(
            "rmse[axis=5]",
            lambda: _mod("metrics").rmse(np.zeros((3, 2)), np.ones((3, 2)), axis=5),
            ("axis",),
        )
    )
    c.append(Case("rmse[scalar]", lambda: _mod("metrics").rmse(1.0, 2.0), ("estimate", "truth")))
    c.append(
        Case(
            "position_errors[empty]",
            lambda: _mod("metrics").position_errors([], []),
            ("estimate", "truth"),
        )
    )
    c.append(
        Case(
            "position_errors[str]",
            lambda: _mod("metrics").position_errors([["a", "b"]], [[0, 0]]),
            ("estimate",),
        )
    )
    c.append(Case("error_stats[nan]", lambda: _mod("metrics").error_stats([1.0, NAN]), ("errors",)))
    c.append(Case("error_stats[empty]", lambda: _mod("metrics").error_stats([]), ("errors",)))
    c.append(
        Case("error_stats[complex]", lambda: _mod("metrics").error_stats([1.0, 2j]), ("errors",))
    )
    c.append(Case("ecdf[empty]", lambda: _mod("metrics").ecdf([]), ("errors",)))
    c.append(Case("ecdf[str]", lambda: _mod("metrics").ecdf(["1", "2"]), ("errors",)))

    # --- montecarlo -------------------------------------------------------------------------------------
    c.append(Case("spawn_rngs[n=2.0]", lambda: _mod("montecarlo").spawn_rngs(0, 2.0), ("n",)))
    c.append(Case("spawn_rngs[n=0]", lambda: _mod("montecarlo").spawn_rngs(0, 0), ("n",)))
    c.append(Case("spawn_rngs[seed=-1]", lambda: _mod("montecarlo").spawn_rngs(-1, 2), ("seed",)))
    c.append(Case("spawn_rngs[seed=1.5]", lambda: _mod("montecarlo").spawn_rngs(1.5, 2), ("seed",)))
    c.append(
        Case(
            "spawn_rngs[n=1e12]",
            lambda: _mod("montecarlo").spawn_rngs(0, 10**12),
            ("n",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "run_trials[runs=1e12]",
            lambda: _mod("runner").run_trials(lambda r: 0, 10**12, 0),
            ("runs", "n"),
            heavy=True,
        )
    )
    c.append(
        Case(
            "run_trials[runs=True]",
            lambda: _mod("runner").run_trials(lambda r: 0, True, 0),
            ("runs", "n"),
        )
    )
    c.append(
        Case("run_trials[trial=None]", lambda: _mod("runner").run_trials(None, 2, 0), ("trial",))
    )
    c.append(Case("mc_count[full=1.5]", lambda: _mod("montecarlo").mc_count(1.5, 1), ("full",)))

    # --- drive helpers (Halili) ---------------------------------------------------------------------------
    tx = [0.0, 4.5]
    _array_cases(
        c,
        "slant_range",
        lambda: _mod("doppler_drive").slant_range,
        {"p": [[10.0, -2.5]], "tx": tx},
        ["p", "tx"],
    )
    _scalar_cases(
        c,
        "slant_range",
        lambda: _mod("doppler_drive").slant_range,
        {"p": [[10.0, -2.5]], "tx": tx, "dz": 2.5},
        ["dz"],
        {k: v for k, v in SCALAR_BAD.items() if k != "none"},
    )
    dsg = {"p": [[10.0, -2.5]], "v": [[25.0, 0.0]], "tx": tx, "fc": 1.35e9, "dz": 2.5}
    _array_cases(
        c, "doppler_shift", lambda: _mod("doppler_drive").doppler_shift, dsg, ["p", "v", "tx"]
    )
    _scalar_cases(
        c, "doppler_shift", lambda: _mod("doppler_drive").doppler_shift, dsg, ["fc", "dz"]
    )
    c.append(
        Case(
            "doppler_shift[fc=-1e9]",
            lambda: _mod("doppler_drive").doppler_shift(**{**dsg, "fc": -1e9}),
            ("fc",),
        )
    )
    c.append(
        Case(
            "doppler_shift[fc=0]",
            lambda: _mod("doppler_drive").doppler_shift(**{**dsg, "fc": 0.0}),
            ("fc",),
        )
    )
    c.append(
        Case(
            "doppler_shift[at tx, dz=0]",
            lambda: _mod("doppler_drive").doppler_shift(
                [[0.0, 4.5]], [[1.0, 0.0]], tx, 1.35e9, 0.0
            ),
            ("p", "tx", "dz"),
        )
    )

    # --- tracking: Doppler helpers ---------------------------------------------------------------------------
    for kname in ("nan", "inf", "complex", "str"):
        c.append(
            Case(
                f"doppler_jacobian[s={kname}]",
                lambda k=kname: _mod("tracking.doppler").doppler_jacobian(
                    _bad_array([10.0, -2.5, 25.0, 0.0], k), _setup()
                ),
                ("s",),
            )
        )
        c.append(
            Case(
                f"doppler_model[s={kname}]",
                lambda k=kname: _mod("tracking.doppler").doppler_model(
                    _bad_array([10.0, -2.5, 25.0, 0.0], k), _setup()
                ),
                ("s",),
            )
        )
    c.append(
        Case(
            "doppler_jacobian[s short]",
            lambda: _mod("tracking.doppler").doppler_jacobian([1.0, 2.0], _setup()),
            ("s",),
        )
    )
    c.append(
        Case(
            "doppler_jacobian[setup=None]",
            lambda: _mod("tracking.doppler").doppler_jacobian([1.0, 2, 3, 4], None),
            ("setup",),
        )
    )
    hdr = lambda: _mod("tracking.doppler").HeadingDeadReckoning([0.0, 0.0], [25.0, 0.0])  # noqa: E731
    for k, v in (
        ("nan", NAN),
        ("inf", INF),
        ("str", "1"),
        ("complex", 1j),
        ("none", None),
        ("bool", True),
    ):
        c.append(Case(f"HeadingDeadReckoning.step[dr={k}]", lambda v=v: hdr().step(v), ("dr",)))
    c.append(
        Case(
            "HeadingDeadReckoning[p0=nan]",
            lambda: _mod("tracking.doppler").HeadingDeadReckoning([NAN, 0.0], [1.0, 0.0]),
            ("p0",),
        )
    )
    for p, v in (("tx", [NAN, 0.0]), ("fc", -1.0), ("fc", NAN), ("dt", 0.0), ("dz", NAN)):
        kw = {"tx": np.array([0.0, 4.5]), "dz": 2.5, "fc": 1.35e9, "dt": 0.032, p: v}
        c.append(
            Case(
                f"DopplerSetup[{p}={v!r}]",
                lambda kw=kw: _mod("tracking.doppler").DopplerSetup(**kw),
                (p,),
            )
        )
    c.append(Case("cv_model[dt=nan]", lambda: _mod("tracking.doppler").cv_model(NAN, 0.5), ("dt",)))
    c.append(Case("cv_model[q=-1]", lambda: _mod("tracking.doppler").cv_model(0.1, -1.0), ("q",)))

    # --- tracking: UPF helpers --------------------------------------------------------------------------------
    upf = lambda: _mod("tracking.upf")  # noqa: E731
    for label, w in (
        ("nan", [0.5, NAN]),
        ("negative", [1.5, -0.5]),
        ("zero sum", [0.0, 0.0]),
        ("inf", [INF, 0.0]),
        ("complex", [0.5 + 1j, 0.5]),
        ("str", ["a", "b"]),
        ("empty", []),
    ):
        c.append(
            Case(
                f"effective_sample_size[{label}]",
                lambda w=w: upf().effective_sample_size(w),
                ("weights",),
            )
        )
        c.append(
            Case(
                f"systematic_resample[{label}]",
                lambda w=w: upf().systematic_resample(w, rng()),
                ("weights",),
            )
        )
    c.append(
        Case(
            "systematic_resample[rng=1]", lambda: upf().systematic_resample([0.5, 0.5], 1), ("rng",)
        )
    )
    c.append(Case("merwe_weights[n=0]", lambda: upf().merwe_weights(0, 1.0, 2.0, 0.0), ("n",)))
    c.append(
        Case("merwe_weights[alpha=nan]", lambda: upf().merwe_weights(4, NAN, 2.0, 0.0), ("alpha",))
    )
    c.append(
        Case(
            "UnscentedParticleFilter[n_particles=1e12]",
            lambda: upf().UnscentedParticleFilter(
                _vs_model(),
                np.array([-80.0, 2.0, 20.0, 0.0]),
                np.eye(4),
                rng=rng(),
                n_particles=10**12,
            ),
            ("n_particles",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "UnscentedParticleFilter[n_particles=2.5]",
            lambda: upf().UnscentedParticleFilter(
                _vs_model(),
                np.array([-80.0, 2.0, 20.0, 0.0]),
                np.eye(4),
                rng=rng(),
                n_particles=2.5,
            ),
            ("n_particles",),
        )
    )

    # --- tracking: PCRLB, gate, CV simulation --------------------------------------------------------------------
    pc = lambda: _mod("tracking.pcrlb")  # noqa: E731
    F4, Q4, P4 = np.eye(2), 0.1 * np.eye(2), np.eye(2)
    info = np.stack([np.eye(2)] * 3)
    for label, kw in (
        ("Q=-eye", {"Q": -0.1 * np.eye(2)}),
        ("P0=nonsym", {"P0": np.array([[1.0, 0.9], [0.0, 1.0]])}),
        ("Q=nonsym", {"Q": np.array([[0.1, 0.05], [0.0, 0.1]])}),
        ("info=negative", {"info": -np.stack([np.eye(2)] * 3)}),
        ("info=nonsym", {"info": np.stack([np.array([[1.0, 2.0], [0.0, 1.0]])] * 3)}),
        ("F=nan", {"F": np.array([[1.0, NAN], [0.0, 1.0]])}),
        ("F=complex", {"F": np.eye(2) * 1j}),
    ):
        name = label.split("=")[0]
        c.append(
            Case(
                f"pcrlb[{label}]",
                lambda kw=kw: pc().pcrlb(**{"F": F4, "Q": Q4, "P0": P4, "info": info, **kw}),
                (name,),
            )
        )
    c.append(
        Case("pcrlb_position_rmse[-eye]", lambda: pc().pcrlb_position_rmse(-np.eye(2)), ("bounds",))
    )
    c.append(
        Case(
            "measurement_information[R=-eye]",
            lambda: pc().measurement_information(np.ones((3, 2, 2)), -np.eye(2)),
            ("R",),
        )
    )
    g = lambda: _mod("tracking.gating")  # noqa: E731
    for label, y, S in (
        ("S=-eye", [1.0, 2.0], -np.eye(2)),
        ("S=nonsym", [1.0, 2.0], np.array([[1.0, 0.5], [0.0, 1.0]])),
        ("S=indefinite", [1.0, 2.0], np.array([[1.0, 2.0], [2.0, 1.0]])),
        ("y=nan", [NAN, 2.0], np.eye(2)),
        ("S=nan", [1.0, 2.0], np.array([[1.0, NAN], [NAN, 1.0]])),
        ("y=complex", [1j, 2.0], np.eye(2)),
    ):
        c.append(
            Case(
                f"mahalanobis2[{label}]",
                lambda y=y, S=S: g().mahalanobis2(y, S),
                (label.split("=")[0],),
            )
        )
    cvm = lambda: _mod("tracking.cv")  # noqa: E731
    c.append(Case("cv_transition[period=nan]", lambda: cvm().cv_transition(NAN), ("period",)))
    c.append(Case("cv_process_noise[q=-1]", lambda: cvm().cv_process_noise(0.1, -1.0), ("q",)))
    c.append(
        Case(
            "simulate_cv[steps=1e12]",
            lambda: cvm().simulate_cv([0.0, 0.0, 1.0, 0.0], 0.1, 0.5, 10**12, rng()),
            ("steps",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "simulate_cv[steps=2.5]",
            lambda: cvm().simulate_cv([0.0, 0.0, 1.0, 0.0], 0.1, 0.5, 2.5, rng()),
            ("steps",),
        )
    )
    c.append(
        Case(
            "simulate_cv[x0=nan]",
            lambda: cvm().simulate_cv([NAN, 0.0, 1.0, 0.0], 0.1, 0.5, 3, rng()),
            ("x0",),
        )
    )

    # --- channel: SRS configuration and tensor sizes ---------------------------------------------------------
    ch = lambda: _mod("channel")  # noqa: E731
    srs_scalars = [
        "fc",
        "bandwidth",
        "scs",
        "tx_power_dbm",
        "t_ant",
        "noise_figure_db",
        "clock_bias_sigma",
        "clock_bias_limit",
    ]
    _scalar_cases(
        c,
        "SRSConfig",
        lambda: ch().SRSConfig,
        {},
        srs_scalars,
        {
            k: v
            for k, v in SCALAR_BAD.items()
            if k in ("nan", "inf", "str", "bool", "complex", "none")
        },
    )
    for p, v in (
        ("comb", 0),
        ("comb", 2.5),
        ("n_symbols", 1),
        ("n_symbols", "12"),
        ("n_rb", 10**9),
        ("fc", -5.9e9),
        ("clock_bias_limit", -1e-9),
    ):
        c.append(Case(f"SRSConfig[{p}={v!r}]", lambda p=p, v=v: ch().SRSConfig(**{p: v}), (p,)))
    c.append(
        Case(
            "SRSConfig[n_symbols=1e9]",
            lambda: ch().SRSConfig(n_symbols=10**9),
            ("n_symbols",),
        )
    )
    paths = lambda: _mod("propagation").trace_paths(_tunnel3d(), _array3d(), ue, fc=5.9e9)  # noqa: E731
    c.append(
        Case(
            "channel_tensor[n_tones x n_symbols huge]",
            lambda: ch().channel_tensor(paths(), ch().SRSConfig(), n_tones=10**6, n_symbols=10**6),
            ("n_tones", "n_symbols"),
            heavy=True,
        )
    )
    c.append(
        Case(
            "channel_tensor[n_symbols huge config]",
            lambda: ch().channel_tensor(paths(), ch().SRSConfig(n_symbols=10**7)),
            ("n_symbols", "n_tones"),
            heavy=True,
        )
    )
    c.append(
        Case(
            "channel_tensor[clock_bias=nan]",
            lambda: ch().channel_tensor(paths(), ch().SRSConfig(), clock_bias=NAN),
            ("clock_bias",),
        )
    )
    c.append(
        Case(
            "add_noise[noise_power=-1]",
            lambda: ch().add_noise(np.ones((2, 2, 2)), -1.0, rng()),
            ("noise_power",),
        )
    )
    c.append(
        Case(
            "sample_clock_bias[size=1e12]",
            lambda: ch().sample_clock_bias(rng(), size=10**12),
            ("size",),
            heavy=True,
        )
    )
    c.append(
        Case(
            "sample_clock_bias[sigma=nan]",
            lambda: ch().sample_clock_bias(rng(), sigma=NAN),
            ("sigma",),
        )
    )
    # the ML model with the spatial-wideband term
    wb_good = {
        "H": np.ones((4, 6, 2), complex),
        "element_positions": np.array([[0, 0, 0], [0.005, 0, 0], [0, 0.005, 0], [0.005, 0.005, 0]]),
        "fc": 28e9,
        "tone_spacing": 480e3,
    }
    _scalar_cases(
        c,
        "WidebandProblem",
        lambda: _mod("extraction.ml").WidebandProblem,
        wb_good,
        ["fc", "tone_spacing"],
        {k: SCALAR_BAD[k] for k in ("nan", "inf", "str")} | {"zero": 0.0, "neg": -1.0},
    )
    return c


def build_cli_cases() -> list[CliCase]:
    c = [
        CliCase("mmax --fc=-1e9", ("mmax", "--fc=-1e9", "--no-ura"), ("fc",)),
        CliCase("mmax --fc nan", ("mmax", "--fc", "nan"), ("fc",)),
        CliCase("mmax --R nan", ("mmax", "--R", "nan"), ("R",)),
        CliCase("mmax --R -1", ("mmax", "--R", "-1", "--no-ura"), ("R",)),
        CliCase("mmax --W 0", ("mmax", "--W", "0", "--no-ura"), ("W",)),
        CliCase("mmax --y-u 5", ("mmax", "--y-u", "5", "--no-ura"), ("y_u", "y-u")),
        CliCase("mmax --eps 0", ("mmax", "--eps", "0", "--no-ura"), ("eps_phi", "eps")),
        CliCase("mmax --eps inf", ("mmax", "--eps", "inf", "--no-ura"), ("eps_phi", "eps")),
        CliCase("mmax --M 1", ("mmax", "--M", "1", "--no-ura"), ("M",)),
        CliCase("mmax --M -5", ("mmax", "--M", "-5", "--no-ura"), ("M",)),
        CliCase("mmax --M 100000", ("mmax", "--M", "100000"), ("M",)),
        CliCase("mmax --M 2.5", ("mmax", "--M", "2.5"), ("M",)),
        CliCase(
            "reproduce jiang-crlb --runs 0", ("reproduce", "jiang-crlb", "--runs", "0"), ("runs",)
        ),
        CliCase(
            "reproduce jiang-crlb --runs -3", ("reproduce", "jiang-crlb", "--runs", "-3"), ("runs",)
        ),
        CliCase(
            "reproduce jiang-crlb --runs 1e12",
            ("reproduce", "jiang-crlb", "--runs", str(10**12), "--no-progress"),
            ("runs",),
        ),
        CliCase(
            "reproduce halili --runs 1e18",
            ("reproduce", "halili", "--runs", str(10**18), "--no-progress"),
            ("runs",),
        ),
        CliCase(
            "reproduce jiang-crlb --seed -1",
            ("reproduce", "jiang-crlb", "--seed", "-1", "--runs", "2"),
            ("seed",),
        ),
    ]
    return c
