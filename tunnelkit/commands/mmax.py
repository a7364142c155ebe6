"""``tunnelkit mmax [--R M] [--W M] [--y-u M] [--z-u M] [--fc F ...] [--eps RAD] [--M N]``.

Prints the SR-NF validity bounds (Italiano et al. 2026, eq. 25 and eq. 37), the corrected
second-order bound and the exact Mmax for one geometry, one row per carrier; with ``--M`` also
the verdict for that array. Defaults: the paper's design example (R = 3.5 m, W = 3 m,
y_u = 2.5 m, 5.9 GHz, eps = 0.15 rad).
"""

from __future__ import annotations

import argparse
import json
import re

NAME = "mmax"
HELP = "SR-NF validity: Mmax bounds (eq. 25, eq. 37) and the exact value for a geometry"

_UNITS = {"": 1.0, "hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}


def parse_frequency(text: str) -> float:
    """``"5.9e9"``, ``"5.9GHz"``, ``"28 ghz"`` -> hertz (argparse type)."""
    m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([a-zA-Z]*)\s*", text)
    if not m or m.group(2).lower() not in _UNITS:
        raise argparse.ArgumentTypeError(f"fc: cannot read {text!r} (e.g. 5.9e9, 5.9GHz, 28GHz)")
    try:
        value = float(m.group(1)) * _UNITS[m.group(2).lower()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"fc: cannot read {text!r}") from None
    return value


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--R", type=float, default=3.5, help="UE distance along the tunnel [m] (3.5)")
    p.add_argument("--W", type=float, default=3.0, help="BS-to-wall distance [m] (3.0)")
    p.add_argument(
        "--y-u", dest="y_u", type=float, default=2.5, help="UE transverse coordinate [m], < W (2.5)"
    )
    p.add_argument(
        "--z-u",
        dest="z_u",
        type=float,
        default=0.0,
        help="UE height relative to the array [m] (0: the 2-D theorem)",
    )
    p.add_argument(
        "--fc",
        type=parse_frequency,
        nargs="+",
        default=[5.9e9],
        help="carrier(s), e.g. 5.9GHz 28GHz (default 5.9GHz)",
    )
    p.add_argument(
        "--eps",
        dest="eps_phi",
        type=float,
        default=0.15,
        help="tolerated phase mismatch eps_phi [rad] (0.15)",
    )
    p.add_argument(
        "--M", type=int, default=None, help="also judge an M-antenna ULA and an M x M URA"
    )
    p.add_argument("--no-ura", action="store_true", help="skip the exact M x M URA search")
    p.add_argument("--format", choices=["table", "json"], default="table")


def main(args: argparse.Namespace) -> int:
    from .. import fresnel

    points = [
        dict(
            R=args.R,
            W=args.W,
            y_u=args.y_u,
            z_u=args.z_u,
            fc=fc,
            eps_phi=args.eps_phi,
            label=f"{fc / 1e9:g} GHz",
        )
        for fc in args.fc
    ]
    rep = fresnel.design_report(
        points, title="SR-NF validity (Italiano et al. 2026, Thm 3.1/3.4)", ura=not args.no_ura
    )
    verdicts = []
    if args.M is not None:
        for pt in points:
            geo = (pt["R"], pt["W"], pt["y_u"], pt["fc"])
            mis = fresnel.phase_mismatch(args.M, *geo, z_u=pt["z_u"])
            mis_ura = fresnel.phase_mismatch_ura(args.M, *geo, z_u=pt["z_u"])
            ok, ok_ura = mis <= args.eps_phi, mis_ura <= args.eps_phi
            verdicts.append(
                {
                    "fc": pt["fc"],
                    "M": args.M,
                    "mismatch_rad": mis,
                    "valid": ok,
                    "ura_mismatch_rad": mis_ura,
                    "ura_valid": ok_ura,
                }
            )
            for what, m, v in (("ULA", mis, ok), ("URA (section 4.1)", mis_ura, ok_ura)):
                size = f"{args.M}" if what == "ULA" else f"{args.M} x {args.M}"
                rep.notes.append(
                    f"{pt['label']}, {size} {what}: exact mismatch {m:.4f} rad -> SR-NF "
                    f"{'valid' if v else 'not valid'} (eps = {args.eps_phi:g} rad)"
                )
    if args.format == "json":
        out = json.loads(rep.to_json())
        out["verdicts"] = verdicts
        print(json.dumps(out, indent=2))
    else:
        print(rep.to_table())
    return 0
