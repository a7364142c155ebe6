"""JAVELIN built from roles: every pair of role choices tracked together, bad combinations refused,
and the named designs the factories build."""

import itertools
from dataclasses import replace

import numpy as np
import pytest
from javelin_geometric import geometric_stream, toy_drive, toy_reflectors

from tunnelkit.simulation.analysis import ablation_path
from tunnelkit.tracking.javelin import (
    Associator,
    DelayCheck,
    DopplerClutter,
    FixedBirth,
    FixedNoise,
    JavelinConfig,
    JavelinDesign,
    JointTestUpdater,
    JosephUpdater,
    MeasuredBirth,
    MirrorMotion,
    PathMeasurements,
    RandomWalk,
    ReflectorCurvature,
    ReportedNoise,
    VueCurvature,
    arraydesign,
    designs,
    run_javelin,
)

BS = (0.0, 0.0, 4.8)
SIG = {"phi": np.radians(1.0), "psi": np.radians(1.0), "kappa": 1.0, "d": 0.3}

#: every choice of every role
CHOICES = {
    "noise": [FixedNoise(), FixedNoise(correlated_delta_d=True), ReportedNoise()],
    "associator": [
        Associator(c, s) for c in ("mahalanobis", "likelihood") for s in ("greedy", "gnn")
    ],
    "initiator": [FixedBirth(), FixedBirth(False), MeasuredBirth(), MeasuredBirth(False)],
    "vue_motion": [RandomWalk(), MirrorMotion()],
    "curvature": [ReflectorCurvature(), VueCurvature()],
    "updater": [JosephUpdater(), JointTestUpdater(0.999)],
    "prefilters": [(DelayCheck(),), (DelayCheck(-30.0), DopplerClutter(1.0))],
}


def _pairwise_cover() -> list[dict]:
    """A deterministic set of role combinations in which every pair of choices of two roles
    occurs at least once (greedy covering of the full product)."""
    roles = list(CHOICES)
    idx = {r: range(len(CHOICES[r])) for r in roles}
    need = {
        (a, i, b, j) for a, b in itertools.combinations(roles, 2) for i in idx[a] for j in idx[b]
    }
    chosen = []
    for combo in itertools.product(*(idx[r] for r in roles)):
        pairs = {
            (roles[p], combo[p], roles[q], combo[q])
            for p, q in itertools.combinations(range(len(roles)), 2)
        }
        if pairs & need:
            need -= pairs
            chosen.append(dict(zip(roles, combo)))
        if not need:
            break
    return [{r: CHOICES[r][c[r]] for r in roles} for c in chosen]


def _stream(seed: int, n: int = 40):
    """A toy drive with exact geometry plus noise, each path carrying its covariance."""
    rng = np.random.default_rng(seed)
    P, V = toy_drive(n, 0.1, amplitude=1.0, speed=4.0)
    eps = geometric_stream(
        P,
        V,
        toy_reflectors(),
        rng,
        bs=BS,
        sigma_phi=SIG["phi"],
        sigma_psi=SIG["psi"],
        sigma_kappa=SIG["kappa"],
        sigma_d=SIG["d"],
        sigma_v=0.2,
        clock_bias=lambda r: r.normal(0.0, 3.0),
    )
    cov = np.diag([SIG["phi"] ** 2, SIG["psi"] ** 2, SIG["kappa"] ** 2])
    out = []
    for m in eps:
        n_p = len(m)
        out.append(
            replace(m, cov=np.tile(cov, (n_p, 1, 1)), sigma_d=np.full(n_p, SIG["d"])) if n_p else m
        )
    spd = np.linalg.norm(V, axis=1) + rng.normal(0, 0.2, n)
    hdg = np.arctan2(V[:, 1], V[:, 0]) + rng.normal(0, np.radians(1.0), n)
    return P, out, spd, hdg


def test_the_cover_holds_every_pair():
    cover = _pairwise_cover()
    roles = list(CHOICES)
    for a, b in itertools.combinations(roles, 2):
        seen = {(repr(c[a]), repr(c[b])) for c in cover}
        assert len(seen) == len(CHOICES[a]) * len(CHOICES[b]), (a, b)
    assert len(cover) < 100  # far fewer than the 768 of the full product


def test_every_pair_of_roles_tracks_together():
    """Each combination of the cover tracks the toy drive. The toy source measures eq. 51's
    curvature; a design with the VUE curvature gets the same paths without curvature (a
    curvature from another model would be a wrong measurement, not a role combination)."""
    P, eps, spd, hdg = _stream(11)
    far = [replace(m, kappa=np.full(len(m), np.nan)) if len(m) else m for m in eps]
    cfg = JavelinConfig(base_station=BS, sigma_p0_ue=1.0)  # the paper sigmas, above the noise
    for roles in _pairwise_cover():
        design = JavelinDesign(cfg, **roles)
        stream = far if isinstance(design.curvature, VueCurvature) else eps
        run = run_javelin(stream, spd, hdg, 0.1, P[0], design)
        err = np.linalg.norm(run.estimates[:, :2] - P[:, :2], axis=1)
        assert np.all(np.isfinite(run.estimates)), design.describe()
        assert np.sqrt(np.mean(err**2)) < 1.0, (design.describe(), float(np.sqrt(np.mean(err**2))))


def test_reported_noise_without_reported_covariances_is_a_fault_per_epoch():
    P, eps, spd, hdg = _stream(3, n=5)
    bare = [PathMeasurements.from_arrays(m.phi, m.psi, m.kappa, m.d, m.v) for m in eps]
    d = JavelinDesign(JavelinConfig(base_station=BS, sigma_p0_ue=1.0), noise=ReportedNoise())
    run = run_javelin(bare, spd, hdg, 0.1, P[0], d, keep_reports=True)
    assert all(any("no reported covariance" in f for f in r.faults) for r in run.reports)


@pytest.mark.parametrize(
    ("kw", "match", "exc"),
    [
        ({"noise": "fixed"}, "^noise", TypeError),
        ({"associator": "gnn"}, "^associator", TypeError),
        ({"initiator": FixedNoise()}, "^initiator", TypeError),
        ({"vue_motion": VueCurvature()}, "^vue_motion", TypeError),
        ({"curvature": MirrorMotion()}, "^curvature", TypeError),
        ({"updater": None}, "^updater", TypeError),
        ({"config": {}}, "^config", TypeError),
        ({"prefilters": (DopplerClutter(1.0),)}, "^prefilters", ValueError),
        ({"prefilters": (DelayCheck(), DelayCheck(-1.0))}, "^prefilters", ValueError),
        (
            {"prefilters": (DelayCheck(), DopplerClutter(), DopplerClutter())},
            "^prefilters",
            ValueError,
        ),
        ({"prefilters": DelayCheck()}, "^prefilters", TypeError),
    ],
)
def test_bad_roles_are_refused_naming_the_role(kw, match, exc):
    with pytest.raises(exc, match=match):
        JavelinDesign(**kw)


@pytest.mark.parametrize(
    ("build", "match"),
    [
        (lambda: Associator(cost="nearest"), "^cost"),
        (lambda: Associator(solver="jpda"), "^solver"),
        (lambda: FixedNoise(correlated_delta_d=1), "^correlated_delta_d"),
        (lambda: FixedBirth(update_at_birth="no"), "^update_at_birth"),
        (lambda: FixedBirth(doppler_sign=0.5), "^doppler_sign"),
        (lambda: JointTestUpdater(0.0), "^probability"),
        (lambda: DelayCheck(float("nan")), "^min_d"),
        (lambda: DopplerClutter(-1.0), "^margin"),
        (lambda: ReportedNoise(fallback=ReportedNoise()), "^fallback"),
    ],
)
def test_bad_role_arguments_name_the_parameter(build, match):
    with pytest.raises((TypeError, ValueError), match=match):
        build()


def test_named_designs():
    p, o = designs.paper(), designs.ours()
    assert p == JavelinDesign()  # the paper's design is the default
    assert o.associator.solver == "gnn" and isinstance(o.vue_motion, MirrorMotion)
    assert o.initiator.update_at_birth is False and o.prefilters[1] == DopplerClutter(1.0)
    assert isinstance(designs.paper_vue().curvature, VueCurvature)
    assert designs.ours_ml().config.sigma_kappa == designs.ML_ERRORS_SEED0["kappa_m"]
    assert designs.ours_ml().updater == JointTestUpdater(0.999)
    # ours step on the midpoint of two messages, the paper's on eq. 62's held one; either is told
    assert o.config.motion_step == "midpoint" and p.config.motion_step == "held"
    assert designs.ours(motion_step="held").config.motion_step == "held"
    # the array design's tracker runs the held step its bounds over a drive model
    assert (
        arraydesign.array_design({"d": 1e-3, "direction": 1e-4, "kappa": 0.01}).config.motion_step
        == "held"
    )
    a = arraydesign.array_design({"d": 1e-3, "direction": 1e-4, "kappa": 0.01}, min_d=-30.0)
    assert a.requires_reported_covariance() and a.min_d == -30.0
    assert isinstance(a.updater, JointTestUpdater) and isinstance(a.initiator, MeasuredBirth)
    assert a.associator.cost == "likelihood" and a.config.sigma_delta_d == pytest.approx(
        np.sqrt(2) * 1e-3
    )
    with pytest.raises(ValueError, match=r"^crlb"):
        arraydesign.array_design({"d": np.nan, "direction": 1.0, "kappa": 1.0})
    # numbers go to the config, roles replace roles
    assert designs.paper(sigma_kappa=3.0).config.sigma_kappa == 3.0
    with pytest.raises(ValueError, match=r"^zeta"):
        designs.paper(zeta=2)
    steps = list(ablation_path().values())
    assert steps[0] == designs.paper() and steps[-1] == designs.ours()


def test_reported_noise_on_a_route_without_covariances_is_refused():
    from tunnelkit import simulation

    drive = simulation.simulate_drive(
        "italiano2026-straight", np.random.default_rng(0), condition="L", n_epochs=1
    )
    assert not drive.reports_covariance
    d = designs.paper(noise=ReportedNoise())
    with pytest.raises(ValueError, match=r"^design, drive: the noise role ReportedNoise"):
        simulation.evaluate(drive, d)
