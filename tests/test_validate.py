import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import _validate as v


def test_validators():
    assert v.positive("x", 2) == 2.0
    assert v.integer("n", np.int64(3), minimum=1) == 3
    assert v.probability("p", 0.5) == 0.5
    for call, exc, match in [
        (lambda: v.positive("sigma", 0.0), ValueError, "sigma: must be > 0"),
        (lambda: v.positive("sigma", float("nan")), ValueError, "sigma: must be finite"),
        (lambda: v.positive("sigma", "1"), TypeError, "sigma: expected a real number"),
        (lambda: v.integer("M", 2.0), TypeError, "M: expected an integer"),
        (lambda: v.integer("M", 1, minimum=2), ValueError, "M: must be >= 2"),
        (lambda: v.probability("p", 1.0), ValueError, r"p: must lie in \(0, 1\)"),
        (lambda: v.finite_array("H", [[1.0, np.nan]]), ValueError, "H: contains NaN"),
        (lambda: v.finite_array("H", [1.0], ndim=2), ValueError, "H: expected 2-D"),
        (lambda: v.vector("p", [1.0, 2.0], 3), ValueError, "p: expected 3 coordinates"),
        (lambda: v.rng_or_error("rng", None), TypeError, "rng: expected a numpy.random.Generator"),
    ]:
        with pytest.raises(exc, match=match):
            call()


def test_quick_mode_and_counts(monkeypatch):
    monkeypatch.setenv("TUNNELKIT_QUICK", "1")
    assert tk.quick_mode() and tk.mc_count(1000, 10) == 10
    monkeypatch.setenv("TUNNELKIT_QUICK", "0")
    assert not tk.quick_mode() and tk.mc_count(1000, 10) == 1000


def test_spawned_streams_are_reproducible_and_independent():
    a = [r.standard_normal() for r in tk.montecarlo.spawn_rngs(5, 3)]
    b = [r.standard_normal() for r in tk.montecarlo.spawn_rngs(5, 3)]
    assert a == b and len(set(a)) == 3
    out = tk.montecarlo.run_trials(lambda r: r.integers(100), 4, seed=1)
    assert out == tk.montecarlo.run_trials(lambda r: r.integers(100), 4, seed=1)


def test_lazy_submodules():
    assert tk.constants.C == 299_792_458.0 and tk.constants.wavelength(5.9e9) == pytest.approx(
        0.0508, abs=1e-4
    )
    with pytest.raises(AttributeError):
        tk.not_a_module  # noqa: B018
