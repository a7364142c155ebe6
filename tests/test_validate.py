import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import _domains as dom
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
    out = tk.runner.run_trials(lambda r: r.integers(100), 4, seed=1)
    assert out == tk.runner.run_trials(lambda r: r.integers(100), 4, seed=1)


def test_lazy_submodules():
    assert tk.constants.C == 299_792_458.0 and tk.constants.wavelength(5.9e9) == pytest.approx(
        0.0508, abs=1e-4
    )
    with pytest.raises(AttributeError):
        tk.not_a_module  # noqa: B018


# --- the strict validators and the domain checks ---------------------------------------------


@pytest.mark.parametrize(
    "value, exc, match",
    [
        ([1.0, 2.0 + 1e-3j], TypeError, "x: expected real numbers, got complex"),
        (np.array([1.0, 2.0], dtype=complex), TypeError, "x: expected real numbers, got complex"),
        ("0.1", TypeError, "x: expected numbers, got text"),
        (["0.1", "0.2"], TypeError, "x: expected real numbers, got text"),
        ([True, False], TypeError, "x: expected real numbers, got booleans"),
        (None, TypeError, "x: expected an array of numbers, got None"),
        ([[1.0, 2.0], [3.0]], TypeError, "x: expected an array of numbers"),
        ([1.0, np.inf], ValueError, "x: contains NaN or infinite"),
    ],
)
def test_finite_array_refuses_what_is_not_a_real_number(value, exc, match):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning either: the error comes first
        with pytest.raises(exc, match=match):
            v.finite_array("x", value)


def test_finite_array_keeps_real_input_and_complex_when_asked():
    a = np.array([1.0, 2.0])
    assert v.finite_array("x", a) is a  # float input is not copied
    np.testing.assert_array_equal(v.finite_array("x", [1, 2]), [1.0, 2.0])
    z = v.finite_array("H", [1j, 2.0], dtype=complex)
    assert z.dtype == complex and z[0] == 1j


@pytest.mark.parametrize("value", [10.5, 10.0, True, np.float64(3.0), "10", None])
def test_counts_must_be_integers(value):
    with pytest.raises(TypeError, match="shape: expected an integer"):
        v.integer("shape", value)


def test_integer_bounds_and_scalars():
    assert v.integer("n", np.int32(7), minimum=1, maximum=7) == 7
    with pytest.raises(ValueError, match="n: must be <= 7"):
        v.integer("n", 8, maximum=7)
    for bad, exc in (
        (1 + 1j, TypeError),
        (np.array([1.0, 2.0]), TypeError),
        (np.bool_(1), TypeError),
    ):
        with pytest.raises(exc, match="fc:"):
            v.positive("fc", bad)
    assert v.real("y", np.float32(-2.5)) == -2.5


def test_domain_checks():
    np.testing.assert_array_equal(v.cosine("cos_i", [0.0, 1.0]), [0.0, 1.0])
    with pytest.raises(ValueError, match=r"cos_i: must lie in \[0, 1\], got 5.0"):
        v.cosine("cos_i", 5.0)
    w = dom.weights("weights", [[0.0, 1.0], [2.0, 2.0]])
    assert w.shape == (2, 2)
    for bad, match in (([0.5, -0.1], ">= 0"), ([0.0, 0.0], "positive sum"), ([], "at least one")):
        with pytest.raises(ValueError, match=f"weights: .*{match}"):
            dom.weights("weights", bad)
    dom.spd_matrix("F", [[2.0, 0.5], [0.5, 1.0]])
    for bad, match in (
        (-np.eye(2), "not positive definite"),
        ([[2.0, 1.0], [0.0, 2.0]], "not symmetric"),
        (np.ones((2, 3)), "square"),
    ):
        with pytest.raises(ValueError, match=f"F: .*{match}"):
            dom.spd_matrix("F", bad)
    with pytest.raises(ValueError, match="stations: need at least 2 stations, got 1"):
        dom.distinct_points("stations", [[0.0, 0.0]], dim=2)
    with pytest.raises(ValueError, match="stations: need at least 2 distinct stations"):
        dom.distinct_points("stations", [[1.0, 2.0], [1.0, 2.0]], dim=2)
    assert v.choice("kinds", "los", ("los", "wall")) == "los"
    with pytest.raises(TypeError, match="front_only: expected True or False"):
        v.boolean("front_only", "no")


def test_findings_of_the_issue_raise_naming_the_parameter():
    from tunnelkit import crlb, metrics, positioning, propagation
    from tunnelkit import doppler_drive as drive
    from tunnelkit.channel import SRSConfig
    from tunnelkit.tracking import pcrlb, upf
    from tunnelkit.tracking.gating import mahalanobis2

    rng = np.random.default_rng(0)
    cases = [
        (lambda: crlb.crlb_trace(-np.eye(2)), "F: singular or not positive definite"),
        (
            lambda: crlb.crlb_trace([[2.0, 1.0], [0.0, 2.0]]),
            "F: a Fisher information matrix must be symmetric",
        ),
        (
            lambda: positioning.tswls([[0.0, 0.0]], [30.0], [0.1], 0.5, 0.01),
            "stations: need at least 2",
        ),
        (
            lambda: positioning.tswls([[0, 0], [0, 0]], [30, 30], [0.1, 0.1], 0.5, 0.01),
            "stations: need at least 2 distinct",
        ),
        (
            lambda: pcrlb.pcrlb_position_rmse(-np.eye(2)),
            "bounds: must be symmetric positive semi-definite",
        ),
        (lambda: mahalanobis2([1.0, 2.0], -np.eye(2)), "S: must be symmetric positive definite"),
        (lambda: propagation.fresnel_te(np.nan, 0.5), "eps_r: must be finite"),
        (lambda: propagation.fresnel_te(5.24, 5.0), r"cos_i: must lie in \[0, 1\]"),
        (
            lambda: drive.doppler_shift([[1.0, 0.0]], [[1.0, 0.0]], [0.0, 4.5], -1e9),
            r"fc: expected 1e\+08 to 3e\+11 Hz",
        ),
        (lambda: crlb.wrap_angle([0.1, np.nan]), "a: contains NaN"),
        (lambda: drive.slant_range([[np.nan, 0.0]], [0.0, 4.5]), "p: contains NaN"),
        (lambda: upf.effective_sample_size([0.5, np.nan]), "weights: contains NaN"),
        (lambda: upf.systematic_resample([1.5, -0.5], rng), "weights: must be >= 0"),
        (lambda: metrics.rmse([], []), "estimate: expected positions"),
        (lambda: metrics.rmse(np.zeros((0, 2)), np.zeros((0, 2))), "estimate, truth: no positions"),
        (lambda: SRSConfig(tx_power_dbm=np.nan), "tx_power_dbm: must be finite"),
        (
            lambda: propagation.lane_trajectory(
                x_start=0, x_end=10, speed=1, period=1, y=np.nan, height=1
            ),
            "y: must be finite",
        ),
    ]
    for call, match in cases:
        with pytest.raises((ValueError, TypeError), match=match):
            call()
    tun = propagation.semicircular_tunnel()
    arr = tk.arrays.make_array(2, 2, fc=5.9e9, azimuth=0.0, elevation=-0.5, origin=[0, 0, 4.8])
    with pytest.raises(ValueError, match="kinds: expected one or more of"):
        propagation.trace_paths(tun, arr, [10.0, -2.0, 1.5], fc=5.9e9, kinds=("bogus",))


# --- the memory budget ---------------------------------------------------------------------------


@pytest.fixture
def budget(monkeypatch):
    from tunnelkit import budget as b

    monkeypatch.delenv(b.ENV, raising=False)
    prev = b.set_memory_budget(None)
    yield b
    b.set_memory_budget(prev)


def test_budget_default_env_and_override(budget, monkeypatch):
    assert budget.memory_budget() == 2 * 1024**3
    monkeypatch.setenv(budget.ENV, "512MiB")
    assert budget.memory_budget() == 512 * 2**20
    monkeypatch.setenv(budget.ENV, "4e9")
    assert budget.memory_budget() == 4_000_000_000
    budget.set_memory_budget("1GB")
    assert budget.memory_budget() == 10**9  # the function wins over the variable
    budget.set_memory_budget(None)
    monkeypatch.setenv(budget.ENV, "lots")
    with pytest.raises(ValueError, match="TUNNELKIT_MEMORY_BUDGET: cannot read 'lots'"):
        budget.memory_budget()
    with pytest.raises(ValueError, match="nbytes: must be a positive"):
        budget.set_memory_budget(-1)


def test_budget_error_names_parameter_and_size(budget):
    with pytest.raises(
        ValueError,
        match=r"n_particles: would need 29.1 TiB \(10\^12 elements of 32 B\), above the memory budget of 2 GiB",
    ):
        budget.check_elements("n_particles", 10**12, 32)
    budget.check_elements("n", 2**28, 8)  # exactly 2 GiB is allowed


def test_sizes_are_checked_before_allocating(budget):
    from tunnelkit import arrays, fresnel, propagation, reproduce, runner

    with pytest.raises(ValueError, match="n_rows, n_cols: would need 596 GiB"):
        arrays.make_array(10**5, 10**5, fc=5.9e9, azimuth=0.0, elevation=0.0)
    with pytest.raises(ValueError, match=r"n_facets: would need 3\.81 GiB"):
        propagation.semicircular_tunnel(n_facets=10**6)
    with pytest.raises(ValueError, match="runs: would need 931 TiB"):
        runner.run_trials(lambda r: 0, 10**12, 0)
    with pytest.raises(ValueError, match="runs: would need"):
        reproduce.run("halili", runs=10**18)
    with pytest.raises(ValueError, match="M: would need"):
        fresnel.phase_mismatch_ura(100_000, 3.5, 3.0, 2.5, 5.9e9)
    with pytest.raises(ValueError, match="m_limit: would need"):
        fresnel.mmax_exact(3.5, 3.0, 2.5, 5.9e9, 0.15, m_limit=10**12)
    from tunnelkit import design, rt
    from tunnelkit import doppler_drive as drive

    with pytest.raises(ValueError, match=r"n_boot: would need 156 GiB \(1000000000 resamples"):
        design.bootstrap_quantile_ci(np.ones((20, 30)), 0.9, np.random.default_rng(0), n_boot=10**9)
    paths = rt.ElementPaths(*(np.zeros((4, 1)),) * 3, np.ones((4, 1), bool),
                            np.zeros((4, 1), int), np.zeros((4, 1), bool), np.zeros((4, 1), int))  # fmt: skip
    with pytest.raises(
        ValueError, match=r"n_tones, n_symbols: would need .* \(4 x 1000000000 x 12 complex"
    ):
        rt.element_tensor(paths, 120e3, 10**9, 1e-5, 12)
    with pytest.raises(ValueError, match=r"n_bins: would need 2 TiB \(211 epochs x 100000000 bins"):
        drive.delay_doppler_profiles(drive.make_drive(), n_bins=10**8)
    budget.set_memory_budget(10**4)  # a small budget turns an ordinary array into an error
    with pytest.raises(ValueError, match="n_rows, n_cols: would need 100 KiB"):
        arrays.make_array(40, 40, fc=5.9e9, azimuth=0.0, elevation=0.0)
    budget.set_memory_budget(None)
    assert arrays.make_array(40, 40, fc=5.9e9, azimuth=0.0, elevation=0.0).M == 1600


def test_duplicate_elements_match_brute_force():
    from tunnelkit import arrays

    rng = np.random.default_rng(3)
    for trial in range(20):
        p = np.zeros((30, 3))
        p[1:, :2] = rng.uniform(-1, 1, (29, 2))
        if trial % 2:
            i, j = rng.choice(np.arange(1, 30), 2, replace=False)
            p[j, :2] = p[i, :2] + rng.uniform(-1, 1, 2) * 1e-12
        d = np.linalg.norm(p[:, None, :2] - p[None, :, :2], axis=-1)
        d[np.diag_indices_from(d)] = np.inf
        brute = np.min(d) <= 1e-9 * np.max(np.abs(p))
        if brute:
            with pytest.raises(ValueError, match="positions: two elements coincide"):
                arrays.check_element_positions("positions", p)
        else:
            arrays.check_element_positions("positions", p)
        assert brute == bool(trial % 2)


def test_mmax_json_marks_a_capped_search(capsys, monkeypatch):
    """A search that hits its cap is marked as a lower bound (the caps lowered here: at the
    package's caps of 2^20 and 1024 antennas no tolerance up to pi rad reaches them)."""
    import functools
    import json

    from tunnelkit import cli
    from tunnelkit.fresnel import summary

    for name, cap in (("mmax_exact", 8), ("mmax_exact_ura", 4)):
        monkeypatch.setattr(summary, name, functools.partial(getattr(summary, name), m_limit=cap))
    monkeypatch.setattr(summary, "M_LIMIT", 8)
    monkeypatch.setattr(summary, "M_LIMIT_URA", 4)
    with pytest.warns(RuntimeWarning, match="returned as a lower bound"):
        assert cli.main(["mmax", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)["rows"][0]
    assert row["exact ULA"] == ">= 8" and row["exact URA MxM"] == ">= 4"
    monkeypatch.undo()  # the package's caps
    assert row["eq.25/exact"] is None
    assert cli.main(["mmax", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)["rows"][0]
    assert row["exact ULA"] == 15 and row["exact URA MxM"] == 11


def test_interval_refuses_nan_reversed_and_wrong_length():
    assert dom.interval("ranges", (2.0, 8.0), lower=1e-3) == (2.0, 8.0)
    assert dom.interval("speeds", np.array([-20, 20])) == (-20.0, 20.0)
    for bad, exc in [
        ("x", TypeError),
        (3.0, TypeError),
        ((1.0,), ValueError),
        ((np.nan, 1.0), ValueError),
        ((5.0, 1.0), ValueError),
    ]:
        with pytest.raises(exc, match=r"^ranges"):
            dom.interval("ranges", bad)
    with pytest.raises(ValueError, match=r"^ranges: must be >= 0.001"):
        dom.interval("ranges", (0.0, 1.0), lower=1e-3)


def test_instance_names_the_parameter_and_the_class():
    cfg = tk.channel.SRSConfig()
    assert v.instance("config", cfg, tk.channel.SRSConfig) is cfg
    with pytest.raises(TypeError, match=r"^config: expected a channel\.SRSConfig, got str"):
        v.instance("config", "x", tk.channel.SRSConfig)
    with pytest.raises(TypeError, match=r"^x: expected a dict or a list, got int"):
        v.instance("x", 3, (dict, list), "a dict or a list")


def test_slider_values_are_checked_against_the_slider_range():
    from tunnelkit.widgets.base import float_slider, int_slider, slider_value

    assert slider_value("q", 0.5, 0.01, 10.0) == 0.5
    assert slider_value(None, -1.0, 0.0, 1.0) == -1.0  # the explorer's own constant
    for bad, exc in [
        ("x", TypeError),
        (np.nan, ValueError),
        (-1.0, ValueError),
        (11.0, ValueError),
    ]:
        with pytest.raises(exc, match=r"^q"):
            float_slider("q [m^2/s^3]", bad, 0.01, 10.0, 0.01, name="q")
    with pytest.raises(TypeError, match=r"^seed"):
        int_slider("seed", 2.5, 0, 20, name="seed")
    with pytest.raises(ValueError, match=r"^seed"):
        int_slider("seed", -1, 0, 20, name="seed")
    assert int_slider("seed", 3, 0, 20, name="seed").value == 3


def test_record_allow_inf_takes_plus_infinity_only():
    """``record(allow_inf=...)``: a float field that may be +inf (no bound) still refuses NaN,
    -inf, a negative value where it must be >= 0 and text, naming the field."""
    from dataclasses import dataclass

    from tunnelkit._validate import record

    @dataclass
    class Bound:
        limit: float = np.inf

        def __post_init__(self):
            record(self, nonnegative=("limit",), allow_inf=("limit",))

    assert Bound().limit == np.inf and Bound(2.0).limit == 2.0
    for bad, exc in (
        (np.nan, ValueError),
        (-np.inf, ValueError),
        (-1.0, ValueError),
        ("x", TypeError),
    ):
        with pytest.raises(exc, match=r"^limit: "):
            Bound(bad)


def test_indices_are_integers_in_range_and_name_the_parameter():
    from tunnelkit._domains import indices

    np.testing.assert_array_equal(indices("keep", [2, 0], 3), [2, 0])
    assert indices("keep", [], 3).shape == (0,)
    for bad, exc in [("01", TypeError), (np.array([np.nan]), TypeError), (5, TypeError),
                     ([3], ValueError), ([-1], ValueError), ([[0, 1]], ValueError)]:  # fmt: skip
        with pytest.raises(exc, match=r"^keep: "):
            indices("keep", bad, 3)
