"""Generated contracts: every public callable refuses bad arguments with the parameter named.

The callables come from the package itself (:func:`contracts.public_callables`: every public
module's ``__all__``, classes' constructors and public methods), the valid arguments from short
recorded workflows (:mod:`contract_values`), the bad values from each parameter's signature
(:func:`contracts.bad_values`). Nothing here names a callable except :data:`DOCUMENTED`, the
reviewed table of results that are right although no error is raised (a parameter where zero is
valid, ...), each with its reason.

Run as a script for the outcome table (``python tests/test_contracts.py [-v]``, with the tree to
probe first on ``PYTHONPATH``).
"""

from __future__ import annotations

import os
import re
import sys
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import contract_values as cv
from contracts import (
    OUTCOMES,
    Case,
    bad_values,
    chunks,
    hints,
    parameters,
    public_callables,
    run_cases,
)


@dataclass(frozen=True)
class Documented:
    """Callables matching ``target`` (regex on ``module.qualname``), parameters matching
    ``param`` (regex, whole name): bad-value kinds in ``kinds`` may return a result."""

    target: str
    param: str
    kinds: frozenset
    reason: str


def _doc(target, param, kinds, reason):
    return Documented(target, param, frozenset(kinds.split()), reason)


ANY = r"(tunnelkit\.)?.*"
DOCUMENTED: tuple[Documented, ...] = (
    _doc(
        r"reckoning\.dead_reckoning|simulation\.drives\.DriveData|tracking\.javelin\.motion\."
        r"midpoint_messages",
        r"speed_msg|heading_msg|speed|heading",
        "nan",
        "NaN marks a V2X message lost: dead reckoning holds the last one (the docstring's "
        "contract), the tracker predicts with the last one",
    ),
    _doc(
        r"reckoning\.dead_reckoning",
        r"start|speed_msg|heading_msg",
        "shape",
        "leading axes are drives (the docstring's contract), each integrated alone",
    ),
    _doc(
        r"studies\.attribution\.(AttributionRow|ConfigSummary)",
        r".*_(deg|m|share|s)",
        "nan",
        "NaN is 'nothing measured' (no path of that kind, no noisy draw): the record's docstring",
    ),
    _doc(
        r"studies\.nuisance\.(ModelRow|CostRow)",
        r"(az|el|d)_(med|rms)|residual_share|fix_(med|rms)_m|extract_s|bias_.*|crlb_ratio_.*|.*_over_crlb_.*",
        "nan",
        "NaN is 'nothing measured' (no path of that kind, no noisy draw): the record's docstring",
    ),
    _doc(
        r"extraction\.direct\.visibility\.predicted_model",
        r"second_order",
        "zero",
        "no second-order atom: the masks and the missing facets alone (model 'visibility')",
    ),
    _doc(
        r"extraction\.direct\.fit\.DirectFix",
        r"clock_bias|speed|residual|evaluations",
        "negative huge nan zero",
        "a fit's record: the clock bias [m] has either sign and its support is the route's; the "
        "speed NaN when not fitted, zero or negative along the heading when the fit says so; the "
        "residual share zero on the model's own tensor; the evaluation count any count (the "
        "physically impossible speeds and shares are refused)",
    ),
    _doc(
        r"design\.traceddirect\.DirectDrive",
        r"speed_errors|unmodelled",
        "empty",
        "no fit of the speed on the drive (the speed not used, or every fit flagged); no ok "
        "direct fit on the drive (every fit unconverged or past its gate)",
    ),
    _doc(
        r"extraction\.direct\.fit\.(direct_fix|diffuse_share|DirectProblem(\.with_diffuse)?|DirectFix)"
        r"|design\.traceddirect\.direct_drive",
        r"diffuse",
        "zero",
        "no diffuse atom: the tied fit alone (the default)",
    ),
    _doc(
        r"extraction\.direct\.fit\.(direct_fix|diffuse_share)|design\.traceddirect\.direct_drive",
        r"diffuse_above",
        "zero",
        "the diffuse atoms tried at every fit (the default)",
    ),
    _doc(
        r"extraction\.direct\.fit\.direct_fix|design\.traceddirect\.direct_drive",
        r"second_order",
        "zero",
        "no second-order atom: the direct fit of the first-order paths and the missing facets",
    ),
    _doc(
        r"extraction\.direct\.aperture\.(ApertureProblem|taper_basis)",
        r"order",
        "zero",
        "order 0 is eq. 1 itself, the reference the profile is tested against (number for number)",
    ),
    _doc(
        ANY,
        r"x|y|z|y_u|z_u|x_start|x_end|start|stop|lane|offset|x_center|y_center|origin"
        r"|x0|y_right|lane_y|tx_y",
        "negative zero",
        "a coordinate [m]: any sign, the origin included",
    ),
    _doc(
        ANY,
        r"azimuth|elevation|heading|tilt|tilt_deg|inclination_deg|theta|phi|psi|angle",
        "negative zero",
        "an angle: any sign, zero included",
    ),
    _doc(ANY, r".*_db|snr_db", "negative zero", "a level or offset in dB: any sign"),
    _doc(ANY, r"seed", "zero", "0 is a seed like any other"),
    _doc(
        ANY,
        r"n_epochs",
        "physical",
        "at most the route's epochs: a larger count drives the whole route (a hang is that drive)",
    ),
    _doc(
        r"(tunnelkit\.)?(design\.(records\.DesignRow|verdict\.(judge|recommend))"
        r"|tracking\.javelin\.tracker\.StepReport)",
        r"runs|units|drives_per_unit|n_paths",
        "physical",
        "a count reported or judged, nothing allocated from it",
    ),
    _doc(
        r"(tunnelkit\.)?extraction\.ml\.residual\.peak_threshold",
        r"n_samples",
        "physical",
        "a count in a closed form (the threshold of n cells), nothing allocated",
    ),
    _doc(
        r"(tunnelkit\.)?tracking\.doppler\.approaches\.Track",
        r"speed",
        "physical",
        "a tracker's speed estimates: a diverged filter's output is reported, not refused",
    ),
    _doc(
        r"(tunnelkit\.)?doppler_drive\.config\.DriveConfig",
        r"spacing",
        "physical",
        "the drive's sample spacing [m] (not an element spacing), checked against its length",
    ),
    _doc(
        r"(tunnelkit\.)?design\.sites\.SiteRow(\.along)?",
        r"spacing",
        "physical",
        "the spacing of the sites along the tunnel [m] (not an element spacing), checked against "
        "the tunnel's length",
    ),
    _doc(
        r"(tunnelkit\.)?design\.sites\.SiteRow\.along",
        r"first",
        "negative zero",
        "the first site's x [m], a coordinate along the tunnel: any sign, checked inside it",
    ),
    _doc(
        r"(tunnelkit\.)?design\.longtunnel\.LongTunnelResult",
        r"runs",
        "physical",
        "a count reported, nothing allocated from it",
    ),
    _doc(
        r"design\.verdict\.recommend",
        r"rows",
        "empty",
        "no candidate left (every array failed, reported per array): no recommendation",
    ),
    _doc(
        ANY,
        r"(phase|gain)_sigma_(deg|db)|amplitude|clock_bias|margin|min_d|.*_prob|.*_bias_hz",
        "zero",
        "zero switches the effect off (no error, no motion, no margin, never)",
    ),
    _doc(
        r".*\.ConsiderNoise",
        r"tau_s",
        "inf huge",
        "inf: the repeating error is one draw for the whole drive; any long time constant",
    ),
    _doc(r".*\.ConsiderNoise\.decay", r"dt", "zero huge", "no time passed, or a long gap"),
    _doc(r".*\.bias_slice", r"i", "zero huge", "track 0 is the UE; any track index"),
    _doc(
        r"plots\.(common|tables|tracking|javelin|design|doppler|efficiency|tunnel3d)\..*",
        r"title|subtitle|xaxis|yaxis",
        "empty",
        "an empty title or axis label shows none (the default)",
    ),
    _doc(
        r"geometry\.(Plane|line)|arrays\.(ArrayGeometry|make_array)"
        r"|propagation\.surfaces\.(Facet|Box|road_marking|truck_box)",
        r"name",
        "empty",
        "a label only; unnamed is the default",
    ),
    _doc(r"budget\.check_(bytes|elements)", r"what", "empty", "no description: the count is shown"),
    _doc(
        r"extraction\.ml\.resolution\.below_threshold",
        r"resolution",
        "inf",
        "a path alone is infinitely far from any other (separations gives inf)",
    ),
    _doc(
        r"extraction\.ml\.resolution\.outlier_probability",
        r"snr",
        "empty shape",
        "elementwise: one probability per SNR, of the same shape (none for none)",
    ),
    _doc(
        r"geometry\.(Plane\.\w+|mirror)|tunnel2d\.Tunnel2D\.\w+|reflection\.(reflector_point|specular_point)",
        r"p|point|target|q|p_u|p_v",
        "shape",
        "points (..., dim): leading axes vectorise (the docstring's contract)",
    ),
    _doc(
        r"fresnel\.(bounds|exact|mismatch)\.\w+",
        r"R|W|y_u|z_u|lam|eps|p_v|pv|ps|pos|positions",
        "shape",
        "elementwise in the geometry, points (..., 3): any leading shape broadcasts",
    ),
    _doc(
        r"tracking\.gating\.mahalanobis2|tracking\.gating\.ChiSquareGate\.accepts",
        r"y|S|d2",
        "shape",
        "vectorised over leading axes (the docstring's contract)",
    ),
    _doc(
        r"tracking\.virtual_station\.model\.regularized_cholesky",
        r"P",
        "shape",
        "a stack (..., n, n) of covariances is factored matrix by matrix",
    ),
    _doc(
        r"tracking\.gating\.(ChiSquareGate\.accepts|squared_distances)"
        r"|tracking\.reopening\.InnovationGate\.judge",
        r"d2",
        "nan",
        "a non-finite d2 is rejected by the gate (the docstring's contract)",
    ),
    _doc(
        r"tracking\.virtual_station\..*",
        r"z|Z",
        "nan",
        "NaN in a measurement marks a missed epoch: the filter predicts only (with a warning)",
    ),
    _doc(
        r"report\.Report|plots\.(tables\.(table|TableFigure)|javelin\.javelin_table_figure"
        r"|tracking\.table_figure|tunnel3d\.paths_table_figure)",
        r"rows|notes|columns|cells",
        "empty",
        "a table with no rows (its header alone)",
    ),
    _doc(
        r"plots\.fresnel\.ratio_map_figure",
        r"ratio",
        "nan",
        "NaN: no ratio at that point (a capped exact search), shown blank",
    ),
    _doc(
        r"schema\.(spec\.)?(Key|Table)|schemadoc\.render_template",
        r"unit|doc|header",
        "empty",
        "optional text: a unitless key, an undocumented table, no header",
    ),
    _doc(
        r"schema\.(spec\.)?Key",
        r"default",
        "type",
        "any default value: the key's type is checked where a file is read",
    ),
    _doc(
        r"widgets\.base\.slider_value",
        r"value",
        "type nan negative",
        "name=None: the explorer's own constant, passed through unchecked (tested)",
    ),
    _doc(
        r"widgets\.base\.(float_slider|int_slider)",
        r"value",
        "negative",
        "name=None: the explorer's own constant; the range is not applied to it (tested)",
    ),
    _doc(
        r"simulation\.drives\.DriveData",
        r"truth_index|kinds|faults|sources",
        "empty",
        "not recorded (the default): the drive's truth association is optional",
    ),
    _doc(
        r"tracking\.virtual_station\.experiment\.VsExperiment",
        r"scenario",
        "empty",
        "a label only; empty for an experiment built by hand (the default)",
    ),
    _doc(
        r"evaluation\.matching\.match_paths",
        r"paths",
        "empty",
        "no true path: every estimate unmatched",
    ),
    _doc(
        r"evaluation\.matching\.match_paths",
        r"clock_bias",
        "negative",
        "a clock bias takes any sign",
    ),
    _doc(r"geometry\.line", r"A|B|C", "negative", "a line's coefficients take any sign"),
    _doc(
        r"(tunnel2d\.Tunnel2D|propagation\.surfaces\.Tunnel3D)\.contains",
        r"margin",
        "negative",
        "a negative margin also counts points just outside the walls",
    ),
    _doc(
        r"tracking\.doppler\..*",
        r"z|doppler|toa",
        "nan",
        "NaN (or None) is a dropped epoch: the filter predicts only (the docstring's contract)",
    ),
    _doc(
        r"(tracking\.doppler|doppler_drive\.drive)\..*",
        r"doppler|u|u0|dr|dz",
        "negative",
        "a signed quantity: Doppler shift, approach speed, a step back, a height offset",
    ),
    _doc(
        r"(channel|signal_route)\..*",
        r"clock_bias|tx_power_dbm",
        "negative",
        "a clock bias takes any sign; a transmit power in dBm may be below 1 mW",
    ),
    _doc(
        r"fresnel\.summary\.MmaxSummary",
        r"exact_ura",
        "negative",
        "-1 records a skipped URA search (mmax_summary(ura=False))",
    ),
    _doc(
        r"tracking\.virtual_station\.filters\.VsUKF",
        r"kappa",
        "negative",
        "kappa = 3 - n < 0 is the classic choice; n + kappa > 0 is what is required",
    ),
    _doc(
        r"scenarios\.(registry\.(Registry\.(lookup|build)|require|getter)|model\.Scenario)",
        r"where|prefix|paper|description",
        "empty",
        "optional text: no file name, the top-level table, a user file (no paper), no description",
    ),
    _doc(
        r"widgets\.base\.(checkbox|float_slider|int_slider)",
        r"description",
        "empty",
        "a control without a label (the explorer's own text beside it)",
    ),
    _doc(
        r"widgets\.base\.(slider_value|float_slider|int_slider)",
        r"lo",
        "negative",
        "a slider's range may reach below zero",
    ),
    _doc(r"schema\.(spec\.)?Key", r"gt|ge|lt|le", "negative", "a range bound takes any sign"),
    _doc(
        r"runner\.TrialPool\.(map|prepare|gather)",
        r"items|handles",
        "empty",
        "no items: no tasks, an empty list back",
    ),
    _doc(
        r"tracking\.doppler\.filters\.doppler_(model|jacobian)",
        r"s",
        "shape",
        "states (..., 4): leading axes vectorise (the docstring's contract)",
    ),
    _doc(
        r"metrics\.(position_errors|rmse|error_stats|ecdf)|crlb\.\w+|angles\.\w+"
        r"|geometry\.spherical\w*"
        r"|positioning\.(simulate_toa_doa|toa_only_candidates)|arrays\.ArrayGeometry\.\w+"
        r"|tracking\.pcrlb\.\w+|tracking\.reopening\.InnovationGate\.inflation"
        r"|tracking\.virtual_station\.model\.VsModel\.(hx|jacobian|position_fim|simulate)",
        r"p|q|u|a|x|F|errors|estimate|truth|d_hat|jacobians|bounds|S|positions",
        "shape",
        "vectorised over leading axes (..., dim) (each docstring's contract): an extra leading "
        "axis gives the same numbers with that axis (test_extra_leading_axes_vectorise)",
    ),
    _doc(
        r"extraction\.paper\.algorithm1|signal_route\.(measurements\.)?"
        r"(measurements_from_estimates|measure_epoch|Epoch\.with_estimates)",
        r"min_d",
        "negative",
        "min_d = -c b_max: Algorithm 1's delay check widened by the clock bias's support",
    ),
    _doc(
        r"doppler_drive\.config\.DriveConfig",
        r"clock_drift|cfo_hz",
        "negative",
        "a clock drift or a carrier frequency offset takes either sign",
    ),
    _doc(
        r"propagation\.surfaces\.Facet\.contains",
        r"tol",
        "negative",
        "a negative tol counts only points strictly inside the rectangle (the tracer's own use)",
    ),
    _doc(
        r"propagation\.surfaces\.(Facet\.contains|Tunnel3D\.(contains|blocked|require_inside)"
        r"|Box\.blocks)|doppler_drive\.drive\.(slant_range|doppler_shift)",
        r"p|a|b|v",
        "shape",
        "points or segments (..., 3) / (..., 2): leading axes vectorise "
        "(test_extra_leading_axes_vectorise)",
    ),
    _doc(
        r"propagation\.surfaces\.(close_tunnel|semicircular_tunnel)|tunnels\.\w+",
        r"plates|blockers",
        "empty",
        "no road markings, no blockers (the default)",
    ),
    _doc(
        r"propagation\.materials\.\w+",
        r"cos_i",
        "shape",
        "elementwise in the incidence: any shape of cosines",
    ),
    _doc(
        r"extraction\.ml\.fitting\.MLFit",
        r"history|reason",
        "empty",
        "no iterations recorded (the default); no failed test (the fit passed)",
    ),
    _doc(
        r"propagation\.path\.Path",
        r"surface",
        "empty",
        "the direct path reflects off no surface",
    ),
    _doc(
        r"propagation\.path\.Path",
        r"range_rate|velocity|doppler",
        "negative",
        "signed: a receding source has a negative velocity and Doppler shift",
    ),
    _doc(
        r"extraction\.estimates\.PathEstimates",
        r"kappa|kappa_nf",
        "nan",
        "NaN: a far-field path has no curvature (the docstring's contract)",
    ),
    _doc(
        r"doppler_drive\.measurement\.DopplerToaMeasurements",
        r"doppler|toa",
        "nan",
        "NaN marks a dropped epoch (the docstring's contract; ``dropped`` flags it too)",
    ),
    _doc(
        r"rt\.compare\.(compare_paths|worst_errors)",
        r"image|other|rows",
        "empty",
        "an engine may find no path: the rows of the other alone; no rows, no differences",
    ),
    _doc(
        r"rt\.mitsuba\.SurfaceInfo",
        r"material",
        "empty",
        "a user scene's shape that references no material",
    ),
    _doc(
        r"tracking\.javelin\.(measurement\.DelayCheck|arraydesign\.array_design)"
        r"|tracking\.measurements\.PathMeasurements\.(from_arrays|sanitised)"
        r"|design\.montecarlo\.javelin_config",
        r"min_d",
        "negative",
        "min_d = -c b_max: Algorithm 1's delay check widened by the clock bias's support",
    ),
    _doc(
        r"tracking\.javelin\.(manage\.(FixedBirth|static_doppler)|measuredbirth\.MeasuredBirth"
        r"|surfaces\.GeometricBirth)",
        r"doppler_sign|sign",
        "negative",
        "-1 is one of the two signs (the channel's convention, the default); 0, 2, NaN refused",
    ),
    _doc(
        r"tracking\.javelin\.manage\.intersection", r"x_u", "negative", "a coordinate [m]: any sign"
    ),
    _doc(
        r"tracking\.javelin\.state\.JavelinState",
        r"ids|misses|transient",
        "empty",
        "a state without VUE tracks (the default: the UE alone)",
    ),
    _doc(
        r"tracking\.javelin\.(manage\.(ManageResult|manage_tracks)"
        r"|update\.(stack_measurement|JosephUpdater\.stack))",
        r"pairs|born|dead|dynamic|unborn",
        "empty",
        "no associated pair, no birth or death this epoch: the tracker predicts only",
    ),
    _doc(
        r"tracking\.javelin\.(tracker\.Javelin\.(step|run|predict)|runs\.run_javelin)",
        r"speed|heading",
        "nan",
        "NaN (or None) is a missing V2X message: the last one is reused with inflated noise "
        "(the docstring's contract, a fault in the report)",
    ),
    _doc(
        r"tracking\.javelin\.(tracker\.Javelin\.(step|predict)|motion\.(ue_velocity|motion_increment|predict"
        r"|RandomWalk\.increment))",
        r"speed",
        "negative",
        "a measured (V2X) speed carries noise: it dips below zero near a standstill",
    ),
    _doc(
        r"tracking\.measurements\.PathMeasurements(\.from_arrays)?",
        r"phi|psi|kappa|d|v",
        "nan",
        "NaN kappa: far field; NaN d, v: unknown; a NaN angle is dropped by Algorithm 1 "
        "(from_arrays, with a JavelinWarning; the tracker sanitises a hand-built one, "
        "test_directly_built_paths_never_stop_a_run)",
    ),
    _doc(
        r"tracking\.javelin\.update\.StackedMeasurement",
        r"labels",
        "empty",
        "row labels are for reports only: a hand-built measurement may carry none",
    ),
    _doc(
        r"tracking\.javelin\.lostest\.los_test",
        r"d|kappa",
        "nan",
        "a path without a curvature or a delay cannot be tested (the docstring's contract)",
    ),
    _doc(
        r"tracking\.javelin\.tenfiloc\.TeNFiLoc\.plausible_kappa",
        r"kappa|d",
        "nan negative",
        "a plausibility test: NaN, negative or far curvatures answer False; an unknown (NaN) "
        "delay is not compared",
    ),
    _doc(
        r"design\.(verdict\.(share_quantile|gate)|intervals\.(bootstrap|cluster)_quantile_ci)",
        r"values|errors",
        "nan",
        "a non-finite error (no estimate) counts as infinite (the module's contract)",
    ),
    _doc(
        r"design\.verdict\.(share_quantile|gate)",
        r"values",
        "shape",
        "values of any shape pooled / (..., T) gated epoch by epoch (each docstring's contract)",
    ),
    _doc(
        r"design\.render\.over_target",
        r"y",
        "nan",
        "a non-finite value counts as over the target (the docstring's contract)",
    ),
    _doc(
        r"design\.errordraws\.psd_sqrt|tracking\.upf\.systematic_resample",
        r"S|weights",
        "shape",
        "a stack (..., n, n) / a batch (..., N): leading axes vectorise (the docstring's contract)",
    ),
    _doc(
        r"tracking\.upf\.UnscentedParticleFilter(\.run|\.update)?",
        r"z|Z",
        "nan",
        "NaN in a measurement marks a missed epoch: the filter predicts only",
    ),
    _doc(
        r"tracking\.upf\.(UnscentedParticleFilter|merwe_weights)",
        r"kappa",
        "negative",
        "kappa = 3 - n < 0 is the classic choice; n + lambda > 0 is what is required (checked)",
    ),
    _doc(
        r"tracking\.virtual_station\.model\.VsModel\.(residual_z|log_likelihood|z_mean)",
        r"a|b|z|x|sigmas",
        "shape",
        "vectorised over leading axes (..., 2N) / (..., 4) / (..., S, 2N) (the docstring's "
        "contract, test_extra_leading_axes_vectorise)",
    ),
    _doc(
        r"tracking\.virtual_station\.model\.VsModel\.residual_z",
        r"a|b",
        "nan",
        "a NaN component (a missed measurement) stays NaN in the residual: the filters mask it",
    ),
    _doc(
        r"tracking\.doppler\.approaches\.EkfDS\.step",
        r"toa",
        "negative",
        "EKF DS uses no ToA; a ToA <= 0 is no time of flight, which the ToA filters drop with a "
        "warning",
    ),
    _doc(
        r"channel\.(DiffuseSpec\.tone_covariance|diffuse_tensor)",
        r"tau0",
        "negative",
        "a delay with the clock bias in it (channel_tensor passes min(tau + b)): any sign",
    ),
    _doc(
        r"tracking\.javelin\.tracker\.(JavelinRun|StepReport)|tracking\.javelin\.tenfiloc"
        r"\.TeNFiLocFix",
        r"reports|associated|(prior_)?ids|paths",
        "empty",
        "reports not kept (the default), no pair associated, no VUE track (before or after the "
        "step), a fix from no path",
    ),
    _doc(
        r"tracking\.javelin\.update\.(JointTestUpdater\.stack|exclude_inconsistent)",
        r"pairs",
        "empty",
        "no associated pair: nothing to test, the tracker predicts only",
    ),
    _doc(
        r"design\.montecarlo\.MonteCarloResult",
        r"settled",
        "empty",
        "a drive shorter than the settling time has no settled epoch (the RMSE then covers it "
        "all, the docstring's contract)",
    ),
    _doc(
        r"design\.montecarlo\.MonteCarloResult",
        r"errors|rmse_runs",
        "nan",
        "NaN: a run without an estimate there (counted as infinite by the verdict)",
    ),
    _doc(
        r"design\.trackerfix\.BoundRoute",
        r"min_d",
        "negative",
        "min_d = -c b_max: Algorithm 1's delay check widened by the clock bias's support",
    ),
    _doc(
        r"tracking\.upf\.(effective_sample_size|ukf_proposal)",
        r"weights|m_pred|P_pred",
        "shape",
        "a batch (..., N) of weights, means (..., 4) and covariances (..., 4, 4): leading axes "
        "vectorise (the docstring's contract)",
    ),
    _doc(
        r"tracking\.upf\.(ukf_proposal(_reference)?|one_epoch_ess)",
        r"z|Z",
        "nan",
        "NaN in a measurement marks a missed epoch (the filters predict only)",
    ),
    _doc(
        r"tracking\.upf\.ukf_proposal(_reference)?",
        r"kappa",
        "negative",
        "kappa = 3 - n < 0 is the classic choice",
    ),
    _doc(
        r"signal_route\.(raytraced\.tensor_snapshot|measurements\.measure_epoch)"
        r"|signal_route\.route\.SignalRoute\.raytraced_snapshot",
        r"paths",
        "empty",
        "no true path recorded in the snapshot (tensor_snapshot's default)",
    ),
    _doc(
        r"design\.(report|records|confirm)\.(DesignReport|ConfirmedReport)",
        r"warnings",
        "empty",
        "no warning to report",
    ),
    _doc(
        r"evaluation\.tables\.(path_rows|comparison_rows)",
        r"paths",
        "empty",
        "no true path: an empty table, or every estimate unmatched",
    ),
    _doc(
        r"evaluation\.tables\.comparison_rows",
        r"clock_bias",
        "negative",
        "a clock offset: either sign",
    ),
    _doc(
        r"plots\.tunnel3d\.tunnel3d_figure",
        r"arrays|paths",
        "empty",
        "the tunnel alone: no array or no path to draw (the defaults)",
    ),
    _doc(
        r"design\.records\.DesignRow",
        r"reason|gaps",
        "empty",
        "no reason to give (the default: a row with a verdict says why only when it has to); "
        "no gap on the route",
    ),
    _doc(
        r"design\.units\.unit_(quantiles|rmse)",
        r"errors",
        "nan",
        "no estimate at that epoch (a lost track): counted as an infinite error",
    ),
    _doc(
        r"design\.arrayjob\.javelin_config",
        r"min_d",
        "negative",
        "Algorithm 1's delay-check threshold: negative where the route's clock bias allows it",
    ),
    _doc(
        r"design\.achievable\.PredictedError",
        r"reason",
        "empty",
        "no gap on the route: nothing to name",
    ),
    _doc(
        r"design\.confirm\.ConfirmedReport",
        r"confirmation",
        "empty",
        "no candidate left to confirm on the channel route (confirm_report's own case)",
    ),
    _doc(
        r"fresnel\.bounds\.aperture",
        r"M",
        "type",
        "M may be a bound's real value (mmax_fraunhofer): the aperture (M - 1) lambda / 2",
    ),
    _doc(
        r"signal_route\.judging\.(BiasBudget\.match|apply_budget)",
        r"k",
        "zero",
        "epoch 0 is the budget's first epoch",
    ),
    _doc(
        r"signal_route\.judging\.rejudge",
        r"share",
        "zero",
        "no impairment floor: the fit is judged against the noise alone",
    ),
    _doc(
        r"signal_route\.judging\.calibration_share",
        r"phase_sigma_deg|gain_sigma_db",
        "huge",
        "share 1: a calibration error that large leaves no received power to the model",
    ),
    _doc(
        r"tracking\.measurements\.PathMeasurements\.subset",
        r"idx",
        "empty",
        "no row kept: measurements of no path (the route's own case of an empty epoch)",
    ),
    _doc(
        r"extraction\.bounds\.merged_(path|crlb)",
        r"alpha",
        "dtype",
        "a real gain is a complex gain of zero phase",
    ),
    _doc(
        r"extraction\.bounds\.merged_crlb",
        r"noise_power|fc",
        "huge",
        "the information scales as 1 / N0 and k0^2: any positive value gives a finite bound",
    ),
    _doc(
        r"path_consistency\.joint_fisher",
        r"alpha",
        "dtype",
        "a real gain is a complex gain of zero phase",
    ),
    _doc(
        r"path_consistency\.joint_fisher",
        r"noise_power",
        "huge",
        "the information scales as 1 / N0: any positive noise power gives a (small) finite one",
    ),
)


def documented(target: str, param: str, kind: str) -> Documented | None:
    for d in DOCUMENTED:
        if (
            kind in d.kinds
            and re.fullmatch(d.param, param)
            and re.fullmatch(d.target, target.removeprefix("tunnelkit."))
        ):
            return d
    return None


# --- building the suite ----------------------------------------------------------------------


@dataclass
class Suite:
    targets: list
    cases: list[Case]
    baselines: list[Case]
    no_baseline: dict[str, str]  # target -> why no valid call is known
    no_parameters: list[str]


def _instance(owner, targets_by_name, recorded):
    """An instance of ``owner`` from its recorded or filled constructor call."""
    name = f"{owner.__module__}.{owner.__qualname__}"
    t = targets_by_name.get(name)
    if t is None:
        raise cv.NoValue(f"no public constructor for {owner.__qualname__}")
    rec = recorded.get(name)
    kw, missing = cv.fill_arguments(t, rec[1] if rec else None)
    if missing:
        raise cv.NoValue(f"constructor needs {', '.join(missing)}")
    return cv.invoke(t, None, {k: cv.fresh(v) for k, v in kw.items()})


def build_suite() -> Suite:
    import warnings

    targets = public_callables()
    by_name = {t.name: t for t in targets}
    recorded = cv.capture(targets, cv.DRIVERS)
    cases, baselines, no_baseline, no_params = [], [], {}, []
    for t in targets:
        params = parameters(t)
        if not params:
            no_params.append(t.name)
            continue
        rec = recorded.get(t.name)
        kw, missing = cv.fill_arguments(t, rec[1] if rec else None)
        if missing:
            no_baseline[t.name] = f"no valid value for {', '.join(missing)}"
            continue
        this = None
        if t.kind == "classmethod":  # the class it was called through (None: its owner)
            this = rec[0] if rec else None
        if t.kind == "method":
            this = rec[0] if rec else None
            if this is None:
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        this = _instance(t.owner, by_name, recorded)
                except Exception as exc:
                    no_baseline[t.name] = f"no instance of {t.owner.__qualname__}: {exc}"[:160]
                    continue

        def call(t=t, this=this, kw=kw, p=None, bad=None):
            args = {k: cv.fresh(v) for k, v in kw.items()}
            if p is not None:
                args[p] = bad
            return cv.invoke(t, cv.fresh(this) if this is not None else None, args)

        baselines.append(Case(f"{t.name}()", t.name, "", None, call))
        h = hints(t)
        # a checking helper (a function, not a record's constructor) names the parameter its
        # caller passes as ``name``
        helper = t.kind != "class" and isinstance(kw.get("name"), str) and kw["name"]
        alias = (kw["name"],) if helper else ()
        for p in params:
            for bad in bad_values(p, h.get(p.name, p.empty), kw.get(p.name)):
                cases.append(
                    Case(
                        f"{t.name}[{p.name}={bad.label}]",
                        t.name,
                        p.name,
                        bad,
                        lambda call=call, p=p.name, v=bad.value: call(p=p, bad=v),
                        alias if p.name != "name" else (),
                    )
                )
    return Suite(targets, cases, baselines, no_baseline, no_params)


def run_suite(suite: Suite) -> tuple[dict, dict]:
    """({case id: (outcome, detail)}, {target: baseline (outcome, detail)})."""
    base = {}
    for group in chunks(suite.baselines):
        for cid, outcome, detail in run_cases(group):
            base[cid[:-2]] = (outcome, detail)
    results = {}
    for group in chunks(suite.cases):
        for cid, outcome, detail in run_cases(group):
            results[cid] = (outcome, detail)
    return results, base


def outcome_of(case: Case, raw: tuple[str, str]) -> tuple[str, str]:
    outcome, detail = raw
    if outcome in ("silent", "hang"):
        d = documented(case.target, case.param, case.bad.kind)
        if d is not None:
            return "documented", d.reason
    return outcome, detail


def table(rows) -> str:
    by_pkg: dict[str, Counter] = {}
    for case, outcome, _ in rows:
        pkg = ".".join(case.target.split(".")[:2])
        by_pkg.setdefault(pkg, Counter())[outcome] += 1
    head = f"{'package':32s} " + " ".join(f"{o:>10s}" for o in (*OUTCOMES, "total"))
    lines = [head]
    total = Counter()
    for pkg in sorted(by_pkg):
        cnt = by_pkg[pkg]
        total.update(cnt)
        lines.append(
            f"{pkg:32s} "
            + " ".join(f"{cnt[o]:10d}" for o in OUTCOMES)
            + f" {sum(cnt.values()):10d}"
        )
    lines.append(
        f"{'all':32s} "
        + " ".join(f"{total[o]:10d}" for o in OUTCOMES)
        + f" {sum(total.values()):10d}"
    )
    return "\n".join(lines)


OPEN_FILE = Path(__file__).resolve().parent / "contracts_open.txt"
FULL = os.environ.get("TUNNELKIT_CONTRACTS", "") == "full"
# the unit run takes these bad-value kinds of every parameter (each present kind, in this
# order, at most UNIT_PER_PARAMETER); TUNNELKIT_CONTRACTS=full (or the script) runs them all
UNIT_KINDS = (
    "physical",
    "type",
    "nan",
    "negative",
    "shape",
    "inf",
    "zero",
    "empty",
    "complex",
    "dtype",
    "huge",
)
UNIT_PER_PARAMETER = 3


def unit_sample(cases: list[Case]) -> list[Case]:
    """The cases the unit run takes: per parameter the first ``UNIT_PER_PARAMETER`` by kind."""
    groups: dict[tuple[str, str], list[Case]] = {}
    for c in cases:
        groups.setdefault((c.target, c.param), []).append(c)
    out = []
    for group in groups.values():
        ranked = sorted(group, key=lambda c: UNIT_KINDS.index(c.bad.kind))
        seen, pick = set(), []
        for c in ranked:
            if c.bad.kind not in seen:
                seen.add(c.bad.kind)
                pick.append(c)
        out += pick[:UNIT_PER_PARAMETER]
    return out


def read_open() -> dict[str, str]:
    """{callable: recorded open count or 'no-baseline ...'} from ``contracts_open.txt``."""
    out = {}
    for line in OPEN_FILE.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, what = line.split("\t", 1)
            out[name] = what
    return out


def open_counts(rows) -> dict[str, Counter]:
    out: dict[str, Counter] = {}
    for c, outcome, _ in rows:
        if outcome not in ("clear", "documented"):
            out.setdefault(c.target, Counter())[outcome] += 1
    return out


def write_open(suite: Suite, rows) -> None:  # pragma: no cover - the script's --write
    counts = open_counts(rows)
    lines = [
        "# Public callables whose generated contract is not met yet (tests/test_contracts.py).",
        "# name<TAB>open cases (unclear/silent/crash/hang) | no-baseline: why no valid call is known",
        "# A callable not listed must meet its contract; a listed one may not get worse.",
    ]
    for name in sorted(set(counts) | set(suite.no_baseline)):
        if name in suite.no_baseline:
            lines.append(f"{name}\tno-baseline: {suite.no_baseline[name]}")
        else:
            c = counts[name]
            lines.append(
                f"{name}\t{sum(c.values())} " + " ".join(f"{k}={v}" for k, v in sorted(c.items()))
            )
    OPEN_FILE.write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def suite() -> Suite:
    return build_suite()


def test_every_public_callable_is_enumerated_and_has_a_contract(suite):
    """Each public callable with parameters gets generated cases, unless it is listed (with the
    reason) as having no known valid call yet: a new public function without one fails here."""
    listed = read_open()
    assert len(suite.targets) > 500
    for name, why in suite.no_baseline.items():
        assert listed.get(name, "").startswith("no-baseline"), (
            f"{name}: no valid call known ({why}); reach it from a workflow in "
            "tests/contract_values.py or give its parameters defaults"
        )
    names = {t.name for t in suite.targets}
    stale = sorted(n for n, w in listed.items() if n not in names)
    assert not stale, f"listed in {OPEN_FILE.name} but no longer public: {stale}"


def test_bad_arguments_are_refused_with_the_parameter_named(suite):
    cases = suite.cases if FULL else unit_sample(suite.cases)
    results = {}
    for group in chunks(cases):
        for cid, outcome, detail in run_cases(group):
            results[cid] = (outcome, detail)
    rows = [(c, *outcome_of(c, results[c.id])) for c in cases]
    counts = open_counts(rows)
    listed = read_open()
    worse = []
    for name, cnt in sorted(counts.items()):
        allowed = listed.get(name, "0").split()[0]
        allowed = int(allowed) if allowed.isdigit() else 0
        # a case past its 1 s time box depends on the machine's load, not on the code: hangs
        # are reported by the script but never push a callable over its recorded count
        if sum(v for k, v in cnt.items() if k != "hang") > allowed:
            detail = [
                f"{c.id}: {o} ({d})"
                for c, o, d in rows
                if c.target == name and o not in ("clear", "documented")
            ]
            worse.append(
                f"{name}: {sum(cnt.values())} open > {allowed} allowed\n    "
                + "\n    ".join(detail[:6])
            )
    assert not worse, "\n".join(worse)
    if FULL:
        fixed = sorted(n for n, w in listed.items() if w.split()[0].isdigit() and n not in counts)
        assert not fixed, f"meet their contract now, remove from {OPEN_FILE.name}: {fixed}"


def test_extra_leading_axes_vectorise():
    """The documented "shape" results above: functions of points (..., dim) give, for an extra
    leading axis, the same numbers with that axis (not a silently wrong broadcast)."""
    import numpy as np

    from tunnelkit import crlb, geometry, metrics, positioning
    from tunnelkit.arrays import make_array
    from tunnelkit.tracking.virtual_station import experiment

    st = np.array([[0.0, 5.0], [0.0, -5.0], [10.0, 0.0]])
    p = np.array([[30.0, 1.0], [20.0, -1.0]])
    q = np.array([[1.0, 2.0, 3.0], [3.0, -1.0, 2.0]])
    arr = make_array(2, 2, fc=28e9, azimuth=0.3, elevation=0.1)
    F = crlb.fim_toa_doa(p, st, 0.01, 0.5)
    model = experiment("jiang2023-straight").model
    x4 = np.array([[30.0, 1.0, 5.0, 0.1], [20.0, -1.0, 4.0, 0.0]])
    cases = [
        (lambda x: crlb.toa_doa(x, st)[0], p),
        (lambda x: crlb.crlb_rmse(x, st, 0.01, 0.5), p),
        (lambda x: crlb.toa_doa_jacobian(x, st), p),
        (crlb.crlb_trace, F),
        (lambda x: metrics.position_errors(x, x + 1.0), p),
        (geometry.spherical, q),
        (geometry.spherical_jacobian, q),
        (arr.to_local, q),
        (arr.dir_to_world, q),
        (lambda x: positioning.toa_only_candidates(st, x), np.array([30.0, 31.0, 25.0])),
        (crlb.wrap_angle, np.array([4.0, -4.0])),
        (model.hx, x4),
        (model.jacobian, x4),
        (model.position_fim, p),
        (lambda x: model.simulate(x, np.random.default_rng(0)), p),
        (lambda x: model.residual_z(x, model.hx(x4)), model.hx(x4 + 0.5)),
        (lambda x: model.log_likelihood(model.hx(x4), x), x4 + 0.5),
        (lambda x: model.z_mean(x, np.full(3, 1 / 3)), np.stack([model.hx(x4)] * 3, axis=1)),
    ]
    import tunnelkit as tk
    from tunnelkit.doppler_drive import doppler_shift, slant_range
    from tunnelkit.propagation import truck_box

    tun = tk.load_scenario("italiano2026-straight").tunnel()
    box = truck_box(20.0, 0.0)
    pts = np.array([[10.0, 0.5, 1.5], [30.0, -1.0, 2.0]])
    far = pts + np.array([20.0, 0.0, 0.0])
    xy, tx, v2 = p, np.array([0.0, 3.0]), np.array([[10.0, 0.5], [-9.0, 0.0]])
    cases += [
        (lambda x: tun.contains(x), pts),
        (lambda x: tun.require_inside("p", x), pts),
        (lambda x: tun.facets[0].contains(x), pts),
        (lambda x: tun.with_blockers(box).blocked(x, far), pts),
        (lambda x: tun.with_blockers(box).blocked(pts, x), far),
        (lambda x: box.blocks(x, far), pts),
        (lambda x: slant_range(x, tx, 2.0), xy),
        (lambda x: doppler_shift(x, v2, tx, 5.9e9, 2.0), xy),
        (lambda x: doppler_shift(xy, x, tx, 5.9e9, 2.0), v2),
    ]
    for f, x in cases:
        np.testing.assert_allclose(f(x[None, None]), f(x)[None, None], rtol=1e-12)


def main(argv) -> None:  # pragma: no cover - the measurement behind the report
    t0 = time.perf_counter()
    suite = build_suite()
    t1 = time.perf_counter()
    if "--unit" in argv:  # the unit run's sample only
        suite.cases = unit_sample(suite.cases)
    results, base = run_suite(suite)
    t2 = time.perf_counter()
    rows = [(c, *outcome_of(c, results[c.id])) for c in suite.cases]
    verbose = "-v" in argv
    for c, outcome, detail in rows:
        if verbose or outcome not in ("clear", "documented"):
            print(f"{outcome:10s} {c.id}: {detail}")
    for name, why in sorted(suite.no_baseline.items()):
        print(f"no-baseline {name}: {why}")
    for name, (outcome, detail) in sorted(base.items()):
        if outcome != "silent":
            print(f"bad-baseline {name}: {outcome} {detail}")
    kinds = Counter(t.kind for t in suite.targets)
    print()
    print(f"callables: {len(suite.targets)} {dict(kinds)}")
    print(
        f"with cases: {len(suite.baselines)}; no parameters: {len(suite.no_parameters)}; "
        f"no baseline: {len(suite.no_baseline)}; baseline not returning: "
        f"{sum(o != 'silent' for o, _ in base.values())}"
    )
    print(f"cases: {len(suite.cases)}; build {t1 - t0:.1f} s, run {t2 - t1:.1f} s")
    print(table(rows))
    if "--write" in argv:
        write_open(suite, rows)


if __name__ == "__main__":  # pragma: no cover
    main(sys.argv[1:])


def test_physical_probes_come_from_the_declared_ranges(suite):
    """The physical class is generated, not listed: every parameter named like a carrier, a
    speed, a time step, an entry-fix spread or a count gets its probes from
    :mod:`tunnelkit._physical`'s ranges (and the budget), and the unit run takes them first."""
    from tunnelkit import _physical as ph

    phys = [c for c in suite.cases if c.bad.kind == "physical"]
    assert len(phys) > 200
    fcs = {c.target for c in phys if c.param == "fc" and c.bad.label == "GHz-for-Hz"}
    assert len(fcs) > 30
    assert all(c.bad.value > ph.CARRIER_HZ[1] for c in phys if c.bad.label == "above-range"
               and c.param == "fc")  # fmt: skip
    assert {c.id for c in phys} <= {c.id for c in unit_sample(suite.cases)} | {
        c.id for c in phys if c.bad.label not in ("GHz-for-Hz", "faster-than-a-vehicle")
    }
