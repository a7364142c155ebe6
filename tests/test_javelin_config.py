import numpy as np
import pytest

from tunnelkit.tracking import registry
from tunnelkit.tracking.javelin import Javelin, JavelinConfig, TeNFiLoc


def test_paper_defaults():
    c = JavelinConfig.paper()
    assert (c.gate_probability, c.max_misses, c.los_gamma) == (0.99, 1, 0.2)
    assert np.degrees(c.sigma_phi) == pytest.approx(2.0) and np.degrees(
        c.sigma_heading
    ) == pytest.approx(1.0)
    assert (c.sigma_kappa, c.sigma_delta_d, c.sigma_speed, c.sigma_p0) == (1.5, 1.5, 0.2, 10.0)


@pytest.mark.parametrize(
    ("kw", "name"),
    [
        ({"sigma_phi": -0.1}, "sigma_phi"),
        ({"sigma_kappa": 0.0}, "sigma_kappa"),
        ({"sigma_speed": -1.0}, "sigma_speed"),
        ({"gate_probability": 1.0}, "gate_probability"),
        ({"gate_probability": 0.0}, "gate_probability"),
        ({"max_misses": -1}, "max_misses"),
        ({"los_gamma": 1.5}, "los_gamma"),
        ({"sigma_p0_ue": 0.0}, "sigma_p0_ue"),
        ({"base_station": (0, 0)}, "base_station"),
    ],
)
def test_bad_parameters_name_themselves(kw, name):
    with pytest.raises(ValueError, match=f"^{name}"):
        JavelinConfig(**kw)


def test_type_errors_and_with():
    with pytest.raises(TypeError, match=r"^max_misses"):
        JavelinConfig(max_misses=1.5)
    with pytest.raises(ValueError, match=r"^zeta"):
        JavelinConfig().with_(zeta=2)
    assert JavelinConfig().with_(sigma_kappa=3.0).sigma_kappa == 3.0
    with pytest.raises(TypeError, match=r"associator"):
        JavelinConfig(associator="gnn")  # behaviour is a role, not a number


def test_registry_family_loads_lazily():
    fam = registry.family("italiano2026")
    assert fam["JAVELIN"] is Javelin and fam["TeNFiLoc"] is TeNFiLoc
