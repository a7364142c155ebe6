"""Experiments of Jiang et al. 2023, section 5: a scenario at one noise level
(:class:`VsExperiment`, :func:`experiment`) and Monte-Carlo runs of every registered estimator on
the same simulated measurements (:func:`monte_carlo`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._validate import boolean, finite_array, instance, integer, record, rng_or_error
from ...budget import check_elements
from ...montecarlo import spawn_rngs
from ...scenarios import Scenario, load_scenario
from ..registry import family
from .filters import run_estimator
from .model import FAMILY, VsModel, initial_states, model_from_scenario

__all__ = ["VsExperiment", "experiment", "monte_carlo"]


# --- experiments (Jiang section 5) -----------------------------------------------------------------


@dataclass(frozen=True)
class VsExperiment:
    """A scenario at one noise level: ``model``, true states ``truth`` (T, 4), prior covariance ``P0``."""

    model: VsModel
    truth: np.ndarray
    P0: np.ndarray
    scenario: str = ""

    def __post_init__(self) -> None:
        record(self, shapes={"truth": (None, 4), "P0": (4, 4)}, may_be_empty=("scenario",))

    @property
    def times(self) -> np.ndarray:
        return np.arange(self.truth.shape[0]) * self.model.period

    def simulate(self, runs: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """``(Z, x0)``: measurements (runs, T, 2N) and prior means (runs, 4) drawn with ``rng``."""
        runs = integer("runs", runs, minimum=1)
        n = 4 * runs * self.truth.shape[0] * max(self.model.n_stations, 1)
        check_elements("runs", n, what=f"{runs} runs' ranges and bearings")
        rng = rng_or_error("rng", rng)
        Z = self.model.simulate(self.truth[:, :2], rng, size=runs)
        x0 = initial_states(self.truth[0], self.P0, rng, size=runs)
        return Z, x0


def experiment(
    scenario: str = "jiang2023-straight",
    *,
    level: int | tuple[float, float] = 0,
    los: bool = False,
    q: float | None = None,
    p0_sigma=None,
) -> VsExperiment:
    """Model, ground truth and prior of a scenario (its ``[tracking]`` section supplies ``q`` and
    ``p0_sigma`` unless given)."""
    if not isinstance(scenario, str | Scenario):
        raise TypeError(
            f"scenario: expected a scenario name or a Scenario, got {type(scenario).__name__}"
        )
    sc = load_scenario(scenario) if isinstance(scenario, str) else scenario
    model = model_from_scenario(sc, level=level, los=los, q=q)
    traj = sc.trajectory()
    truth = np.concatenate([traj.position, traj.velocity], axis=-1)
    ps = (
        sc.get("tracking.p0_sigma", shape=(2,))
        if p0_sigma is None
        else finite_array("p0_sigma", p0_sigma, shape=(2,))
    )
    if np.any(ps <= 0):
        raise ValueError(f"p0_sigma: must be > 0, got {ps}")
    P0 = np.diag([ps[0] ** 2, ps[0] ** 2, ps[1] ** 2, ps[1] ** 2])
    return VsExperiment(model, truth, P0, sc.name)


def monte_carlo(
    exp: VsExperiment,
    runs: int,
    seed: int | np.random.Generator = 0,
    *,
    names=None,
    options: dict | None = None,
    progress: bool = False,
) -> dict[str, np.ndarray]:
    """Estimates (runs, T, 4) of each registry member on the same simulated runs.

    ``options`` maps an algorithm name to keyword options (e.g. ``{"UPF": {"n_particles": 200}}``).
    Every estimator gets its own child generator of ``seed`` by its position in ``names``, so a
    call with the same ``names`` gives the same numbers. ``progress``: a tqdm bar over the
    estimators (it draws no random numbers).
    """
    from tqdm.auto import tqdm

    instance("exp", exp, VsExperiment)
    if options is not None and not isinstance(options, dict):
        raise TypeError(
            f"options: expected a dict name -> keyword options, got {type(options).__name__}"
        )
    fam = family(FAMILY)
    progress = boolean("progress", progress)
    if names is not None and (isinstance(names, str) or not isinstance(names, list | tuple)):
        raise TypeError(f"names: expected a list of estimator names, got {names!r}")
    if names is not None and not names:
        raise ValueError("names: expected at least one estimator (None: all of them)")
    names = list(fam) if names is None else list(names)
    rng_data, *rng_alg = spawn_rngs(seed, 1 + len(names))
    Z, x0 = exp.simulate(runs, rng_data)
    opts = options or {}
    out = {}
    with tqdm(names, desc=f"{runs} runs", leave=False, disable=not progress) as bar:
        for n, r in zip(bar, rng_alg):
            bar.set_postfix_str(n)
            out[n] = run_estimator(n, exp.model, Z, x0, exp.P0, rng=r, **opts.get(n, {}))
    return out
