"""``tunnelkit design SCENARIO --arrays 4x4 8x8 16x16 [--fc 28GHz] [--bandwidth 400MHz]
[--ideal] [--phase-error-deg X] [--gain-error-db Y] [--wideband/--no-wideband]
[--wideband-model/--no-wideband-model] [--dmc-share S]
[--target T] [--share Q] [--units N] [--drives-per-unit D] [--yield Y] [--max-units C]
[--settle S] [--workers N | --scheduler A] [--trial-timeout S|none] [--mode bound|channel]
[--criterion achievable|srnf] [--confirm [--confirm-units N]] [--channel image|sionna [--traced-tracker auto|los|paths|direct]]
[--start-sigma S] [--no-dead-reckoning] [--format table|json] [--plot FILE.html]``.

Sizes an array for a scenario's tunnel and route (:mod:`tunnelkit.design`): per candidate array
the ideal position error bound, the predicted error under the stated impairments (a first-order
prediction, not a bound), SR-NF validity per surface, and with ``--units`` the Monte-Carlo of the
design's tracker over manufactured units (one calibration draw each, ``--drives-per-unit``
drives): the unit yield (the share of units whose own ``share``-quantile over the settled route
meets ``--target``, Wilson 95 % interval), the pooled quantile with its interval over units, and the
bounds over the drive beside the tracker's RMSE. Undecided arrays get more units until decided or
``--max-units``; the smallest array whose yield interval reaches ``--yield`` is recommended
(``recommendation.route`` the route that decided; ``--confirm``: the bound route's answer re-run
on the channel route, which then decides, :func:`tunnelkit.design.confirm_on_channel`). Every
input, the criterion and the warnings are in the JSON. ``--plot FILE.html`` also writes the answer
as a figure (:func:`tunnelkit.plots.design.design_answer_figure`, plotly.js included, so it opens
offline) and says so on stderr, so the JSON on stdout stays valid.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from dataclasses import replace
from pathlib import Path

from .._physical import MAX_RANGE_M
from ..design.tracedtracker import TRACED_TRACKERS

NAME = "design"
HELP = (
    "size an antenna array for a tunnel: bounds, achievable accuracy, Monte-Carlo, recommendation"
)

_UNITS = {"": 1.0, "hz": 1.0, "khz": 1e3, "mhz": 1e6, "ghz": 1e9}


def _frequency(param: str):
    """argparse type reading ``28GHz``, ``400 MHz``, ``5.9e9``; errors name ``param``."""

    def parse(text: str) -> float:
        m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([a-zA-Z]*)\s*", text)
        try:
            if not m or m.group(2).lower() not in _UNITS:
                raise ValueError
            value = float(m.group(1)) * _UNITS[m.group(2).lower()]
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{param}: cannot read {text!r} (e.g. 28GHz, 400MHz, 5.9e9)"
            ) from None
        if not 0 < value < float("inf"):
            raise argparse.ArgumentTypeError(f"{param}: must be > 0 and finite, got {text!r}")
        return value

    return parse


def positive_arg(param: str, upper: float = float("inf")):
    """argparse type: a number > 0 and finite (at most ``upper``); errors name ``param``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{param}: expected a number, got {text!r}") from None
        if not 0 < value < float("inf"):
            raise argparse.ArgumentTypeError(f"{param}: must be > 0 and finite, got {text!r}")
        if value > upper:
            raise argparse.ArgumentTypeError(f"{param}: at most {upper:g}, got {text!r}")
        return value

    return parse


def _bounded(param: str, lo: float, hi: float):
    """argparse type: a finite number in ``[lo, hi]``; errors name ``param``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{param}: expected a number, got {text!r}") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{param}: must be in [{lo:g}, {hi:g}], got {text!r}")
        return value

    return parse


def _level(param: str, upper: float | None = None):
    """argparse type: a finite number >= 0 (and < ``upper``); errors name ``param``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{param}: expected a number, got {text!r}") from None
        if not value >= 0 or not value < (upper if upper is not None else float("inf")):
            rng = f"[0, {upper:g})" if upper is not None else "a finite number >= 0"
            raise argparse.ArgumentTypeError(f"{param}: must be {rng}, got {text!r}")
        return value

    return parse


def _share(param: str):
    """argparse type: a share in (0, 1); errors name ``param``."""

    def parse(text: str) -> float:
        value = _level(param, 1.0)(text)
        if value == 0:
            raise argparse.ArgumentTypeError(f"{param}: must be in (0, 1), got {text!r}")
        return value

    return parse


def count_arg(param: str, minimum: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{param}: expected an integer, got {text!r}"
            ) from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"{param}: must be >= {minimum}, got {text!r}")
        return value

    return parse


def _html_path(param: str):
    """argparse type: a file path whose directory exists (checked before the sweep runs, not
    after it); errors name ``param``."""

    def parse(text: str) -> Path:
        path = Path(text).expanduser()
        if not text.strip() or path.is_dir():
            raise argparse.ArgumentTypeError(f"{param}: expected a file path, got {text!r}")
        if not path.parent.is_dir():
            raise argparse.ArgumentTypeError(
                f"{param}: the directory {str(path.parent)!r} of {text!r} does not exist"
            )
        return path

    return parse


def _impairments(args: argparse.Namespace, setup, specs):
    """The impairments the options ask for and their name: the calibrated set (or the ideal one,
    ``--ideal``) with each impairment option given replacing its field."""
    from .. import design

    base = "ideal" if args.ideal else "calibrated"
    given = {
        k: v
        for k, v in (
            ("phase_error_deg", args.phase_error_deg),
            ("gain_error_db", args.gain_error_db),
            ("spatial_wideband", args.wideband),
            ("wideband_model", args.wideband_model),
            ("dmc_share", args.dmc_share),
        )
        if v is not None
    }
    if not given:
        return base, base
    if args.wideband is not None and args.wideband_model is None:
        given["wideband_model"] = args.wideband  # the estimator follows the channel
    imp = replace(design.preset_impairments(base, setup, specs), **given)
    return imp, f"{base}, changed: {', '.join(sorted(given))}"


def add_arguments(p: argparse.ArgumentParser) -> None:
    # the main options (at most 15): the question an engineer asks; the rest in advanced groups
    geo = p.add_argument_group("advanced: array, mount and geometry")
    imp = p.add_argument_group(
        "advanced: impairments (the default, a calibrated array: phase 1.5 deg and gain 0.25 "
        "dB per element, 5.6 % of the power diffuse, the spatial-wideband term where the band "
        "calls for it; sources in REFERENCES.md)"
    )
    mc = p.add_argument_group(
        "advanced: Monte-Carlo by manufactured units (each unit one calibration draw, several "
        "drives)"
    )
    rt = p.add_argument_group("advanced: routes, criterion and channel")
    out = p.add_argument_group("advanced: progress and parallel runs")
    p.add_argument("scenario", help="preset name (tunnelkit scenarios) or a .toml path")
    p.add_argument(
        "--arrays",
        nargs="+",
        default=["4x4", "8x8", "16x16"],
        help="candidate arrays: N (a ULA) or NxM (a URA), e.g. 4x4 8x8 16x16",
    )
    geo.add_argument(
        "--spacing", type=positive_arg("spacing"), default=0.5, help="[wavelengths] (0.5)"
    )
    p.add_argument("--fc", type=_frequency("fc"), default=None, help="carrier, e.g. 28GHz")
    p.add_argument("--bandwidth", type=_frequency("bandwidth"), default=None, help="e.g. 400MHz")
    geo.add_argument(
        "--tilt",
        type=_bounded("tilt", -90.0, 90.0),
        default=None,
        help="down-tilt of every array [deg]",
    )
    geo.add_argument(
        "--mount-height", type=float, default=None, help="height of the arrays' centre [m]"
    )
    p.add_argument(
        "--target",
        type=positive_arg("target", MAX_RANGE_M),
        default=0.2,
        help="position error target [m] (0.2)",
    )
    p.add_argument(
        "--share",
        type=float,
        default=0.9,
        help="share of the settled route on which the error must meet the target (0.9)",
    )
    p.add_argument(
        "--ideal",
        action="store_true",
        help="start from the ideal array and eq. 1's channel (no impairment: the optimistic "
        "case) instead of the calibrated one",
    )
    p.add_argument(
        "--phase-error-deg",
        type=_level("phase_error_deg"),
        default=None,
        help="per-element phase calibration error, standard deviation [deg] (1.5; --ideal 0)",
    )
    p.add_argument(
        "--gain-error-db",
        type=_level("gain_error_db"),
        default=None,
        help="per-element gain calibration error, standard deviation [dB] (0.25; --ideal 0)",
    )
    imp.add_argument(
        "--wideband",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the spatial-wideband term (delay across the aperture) in the channel (on where "
        "the band's delay across the largest array exceeds 0.1 cycle; --ideal off)",
    )
    imp.add_argument(
        "--wideband-model",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the estimator models the spatial-wideband term (ML with the per-element delay), so "
        "it leaves no bias; needs --wideband (default: as --wideband; --no-wideband-model: the "
        "estimator fits eq. 1 and carries the term's bias)",
    )
    p.add_argument(
        "--dmc-share",
        type=_level("dmc_share", 1.0),
        default=None,
        help="dense diffuse multipath: share of the received power, in [0, 1) (0.056; --ideal 0)",
    )
    rt.add_argument(
        "--criterion",
        choices=["achievable", "srnf"],
        default="achievable",
        help="achievable: the design's VUE-curvature tracker, SR-NF as information (default); "
        "srnf: an eq. 51 estimator, SR-NF validity a gate",
    )
    rt.add_argument(
        "--eps", type=positive_arg("eps", math.pi), default=0.15, help="eps_phi [rad] (0.15)"
    )
    p.add_argument(
        "--units",
        "--runs",
        dest="units",
        type=count_arg("units", 0),
        default=0,
        help="units of the first batch (0: bounds and predictions only, no recommendation; 20 "
        "to decide); undecided arrays then get as many again until decided or --max-units",
    )
    mc.add_argument(
        "--drives-per-unit",
        type=count_arg("drives_per_unit", 1),
        default=2,
        help="drives per unit (2): a unit's own quantile pools its drives",
    )
    p.add_argument(
        "--yield",
        dest="required_yield",
        type=_share("yield"),
        default=0.95,
        help="required share of units that meet the target on their own (0.95); the "
        "recommendation is the smallest array whose yield's 95 %% interval reaches it",
    )
    mc.add_argument(
        "--max-units",
        type=count_arg("max_units", 1),
        default=200,
        help="cap of the sequential rule: units per array at most (200)",
    )
    mc.add_argument(
        "--settle",
        type=_level("settle"),
        default=1.0,
        help="settle window [s]: the epochs this long after the start (the tracker's start-up "
        "from the entry fix) are left out of the settled route (1)",
    )
    rt.add_argument(
        "--mode",
        choices=["bound", "channel"],
        default="bound",
        help="Monte-Carlo measurements: drawn from the error model (bound, fast) or "
        "synthesised and extracted (channel)",
    )
    rt.add_argument(
        "--confirm",
        action="store_true",
        help="re-run the recommended array (and the smaller ones left undecided) on the channel "
        "route with the same units and seed, and take the recommendation from it (bound mode)",
    )
    rt.add_argument(
        "--confirm-units",
        "--confirm-runs",
        dest="confirm_units",
        type=int,
        default=None,
        help="units per array of the --confirm re-run (default: --units); the channel route "
        "costs minutes per drive, the bound route seconds",
    )
    rt.add_argument(
        "--channel",
        choices=["image", "sionna"],
        default="image",
        help="channel source of --mode channel: eq. 1 from the image method (default) or the "
        "ray-traced channel (Sionna RT, traced once per array and cached; there every epoch's ML "
        "measurements pass a geometry pre-filter and the tracker is told the array's errors "
        "measured on that channel, not the reported CRLB; no impairments)",
    )
    rt.add_argument(
        "--traced-tracker",
        choices=TRACED_TRACKERS,
        default=None,
        help="with --channel sionna: the tracker on the ray-traced channel, the line of sight "
        "alone, told its angle sigmas by its measured elevation from a survey of 3 drives per "
        "array (los), every path the geometry pre-filter keeps told the array's RMS errors "
        "(paths), per array the one whose told model predicts the smaller error (auto, "
        "default), or the line of sight of the direct fit, every atom tied to one UE position "
        "and started from the track's prediction (direct: seconds per epoch, docs/results/"
        "traced-models.md)",
    )
    mc.add_argument(
        "--n-epochs",
        type=count_arg("n_epochs", 1),
        default=None,
        help="first N epochs of the route",
    )
    p.add_argument("--seed", type=count_arg("seed", 0), default=0, help="Monte-Carlo seed (0)")
    mc.add_argument(
        "--start-sigma",
        type=positive_arg("start_sigma"),
        default=None,
        help="the entry fix's standard deviation per axis [m]: the tracker's start and the prior "
        "of the bounds over the drive (default 1, an open-sky fix)",
    )
    mc.add_argument(
        "--dead-reckoning",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="with --units: run each drive also with every measurement dropped (the same "
        "tracker, start and V2X messages) and report its error beside the tracker's, what the "
        "radio adds (on by default; --no-dead-reckoning leaves it out)",
    )
    from .reproduce import add_parallel_arguments, add_trial_timeout

    add_parallel_arguments(out)
    add_trial_timeout(out, "drive", "A direct-tracker drive of a 10 x 10 takes 10-15 minutes of "
                      "one core, longer on a busy machine")  # fmt: skip
    out.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    p.add_argument("--format", choices=["table", "json"], default="table")
    p.add_argument(
        "--plot",
        type=_html_path("plot"),
        default=None,
        metavar="FILE.html",
        help="also write the answer as an interactive figure (HTML): the error along the route "
        "beside the PEB and the prediction, the unit yield per array",
    )


def _stopped(exc: Exception) -> int:
    """A Monte-Carlo run that stopped (a worker lost, or no drive finished in time): the error
    on stderr, exit status 1."""
    hint = ""
    if isinstance(exc, TimeoutError):
        hint = "; on a busy machine, or for slow drives, give a longer --trial-timeout (or none)"
    print(f"tunnelkit design: error: {exc}{hint}", file=sys.stderr)
    return 1


def main(args: argparse.Namespace) -> int:
    from .. import design
    from ..runner import TrialLost, TrialTimeout
    from .reproduce import parallel_kwargs

    try:
        specs = [design.parse_array(a, args.spacing) for a in args.arrays]
    except ValueError as exc:  # the option's name, not the function's parameter
        raise ValueError(f"arrays: {str(exc).removeprefix('spec: ')}") from None
    if args.confirm and (args.mode != "bound" or args.units == 0):
        print(
            "tunnelkit design: error: --confirm re-runs a bound-route answer: it needs --mode "
            "bound and --units > 0",
            file=sys.stderr,
        )
        return 2
    if args.confirm_units is not None and (not args.confirm or args.confirm_units < 1):
        print(
            "tunnelkit design: error: --confirm-units needs --confirm and at least 1 unit",
            file=sys.stderr,
        )
        return 2
    if args.channel != "image" and (args.mode != "channel" or args.units == 0):
        print(
            "tunnelkit design: error: --channel sionna needs --mode channel and --units > 0 "
            "(the bounds and the bound mode use the eq. 1 model)",
            file=sys.stderr,
        )
        return 2
    if args.traced_tracker not in (None, "paths") and args.channel != "sionna":
        print(
            f"tunnelkit design: error: --traced-tracker {args.traced_tracker} tracks on the "
            f"ray-traced channel: it needs --channel sionna (got --channel {args.channel})",
            file=sys.stderr,
        )
        return 2
    setup = design.DesignSetup.from_scenario(
        args.scenario,
        fc=args.fc,
        bandwidth=args.bandwidth,
        tilt_deg=args.tilt,
        mount_height=args.mount_height,
        channel=args.channel,
    )
    impairments, preset = _impairments(args, setup, specs)
    try:
        rep = design.design_sweep(
            setup,
            specs,
            target=args.target,
            share=args.share,
            criterion=args.criterion,
            impairments=impairments,
            eps_phi=args.eps,
            units=args.units,
            drives_per_unit=args.drives_per_unit,
            required_yield=args.required_yield,
            max_units=args.max_units,
            settle=args.settle,
            seed=args.seed,
            mode=args.mode,
            n_epochs=args.n_epochs,
            **({} if args.start_sigma is None else {"start_sigma": args.start_sigma}),
            **({"dead_reckoning": True} if args.dead_reckoning and args.units else {}),
            **({} if args.traced_tracker is None else {"traced_tracker": args.traced_tracker}),
            **parallel_kwargs(args),
            trial_timeout=args.trial_timeout,
            progress=args.units > 0 and args.format == "table" and not args.no_progress,
        )
    except (TrialLost, TrialTimeout) as exc:
        return _stopped(exc)
    rep.settings.update(
        impairments_preset=preset,
        spacing_wl=args.spacing,
        tilt_deg=args.tilt,
        mount_height_m=args.mount_height,
        **({"channel": args.channel} if args.channel != "image" else {}),
    )
    rep.recommendation["route"] = args.mode if args.units else None
    if args.confirm and args.mode == "bound" and args.units:
        try:
            rep = design.confirm_on_channel(
                rep,
                setup,
                units=args.confirm_units,
                **parallel_kwargs(args),
                trial_timeout=args.trial_timeout,
                progress=args.format == "table" and not args.no_progress,
            )
        except (TrialLost, TrialTimeout) as exc:
            return _stopped(exc)
    if all(r.status == "error" for r in rep.rows):
        for r in rep.rows:
            print(f"tunnelkit design: error: {r.reason}", file=sys.stderr)
        return 2
    if args.plot is not None:
        from ..plots.design import design_answer_figure

        try:
            design_answer_figure(rep).write_html(args.plot, include_plotlyjs=True)
        except OSError as exc:
            print(f"tunnelkit design: error: plot: cannot write {exc}", file=sys.stderr)
            return 2
        print(f"figure written to {args.plot}", file=sys.stderr)
    if args.format == "json":
        print(json.dumps(rep.to_json(), indent=2))
    else:
        print(rep.to_table())
    return 0
