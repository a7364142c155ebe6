import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit.scenarios import ScenarioError


def test_presets_load_and_stay_inside_the_tunnel():
    for name in ("jiang2023-straight", "jiang2023-curved"):
        sc = tk.load_scenario(name)
        tun = sc.tunnel()
        tr = sc.trajectory(tun)
        assert len(tr) == 100 and tr.period == pytest.approx(0.1)
        assert np.all(tun.contains(tr.position))
        assert sc.noise_levels()[0] == pytest.approx((np.radians(0.5), 0.1))


def test_straight_trajectory_matches_the_paper():
    tr = tk.load_scenario("jiang2023-straight").trajectory()
    np.testing.assert_allclose(tr.position[0], [10.0, 14.8481])
    np.testing.assert_allclose(np.linalg.norm(tr.velocity, axis=-1), 14.1421, atol=1e-4)


def test_curved_trajectory_is_a_six_metre_lane_change():
    sc = tk.load_scenario("jiang2023-curved")
    tun = sc.tunnel()
    tr = sc.trajectory(tun)
    across = tun.to_tunnel_frame(tr.position)[:, 1]
    assert across[0] == pytest.approx(3.0, abs=1e-3)
    # 100 samples cover 9.9 s of the 10 s manoeuvre
    assert across[-1] - across[0] == pytest.approx(6.0, abs=0.02)
    # velocity integrates to position
    np.testing.assert_allclose(
        np.diff(tr.position, axis=0) / tr.period,
        0.5 * (tr.velocity[1:] + tr.velocity[:-1]),
        atol=1e-9,
    )


def test_unknown_scenario_names_available_ones():
    with pytest.raises(ScenarioError, match=r"unknown scenario 'nope'.*jiang2023-straight"):
        tk.load_scenario("nope")
    with pytest.raises(TypeError, match="name:"):
        tk.load_scenario(3)


GOOD = """
name = "t"
paper = "jiang2023"
[tunnel]
kind = "walls2d"
walls = [[3.0, -3.0, 40.0], [3.0, -3.0, -23.6396]]
[base_station]
position = [0.0, 0.0]
[trajectory]
kind = "piecewise_acceleration"
start = [10.0, 14.8481]
velocity = [10.0, 10.0]
period = 0.1
steps = 10
"""


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        ('name = "t"\n', "", "missing key 'name'"),
        (
            "walls = [[3.0, -3.0, 40.0], [3.0, -3.0, -23.6396]]",
            "walls = [[3.0, -3.0, 40.0]]",
            "'tunnel.walls' must have shape",
        ),
        (
            'kind = "walls2d"',
            'kind = "round"',
            "'tunnel.kind' must be one of \\['walls2d'\\], got 'round'",
        ),
        (
            "walls = [[3.0, -3.0, 40.0], [3.0, -3.0, -23.6396]]",
            "walls = [[0.0, 0.0, 40.0], [3.0, -3.0, 1.0]]",
            "tunnel.walls: A, B: degenerate",
        ),
        ("steps = 10", 'steps = "ten"', "'trajectory.steps' must be an integer"),
        ("period = 0.1", "period = -0.1", r"'trajectory.period' must be > 0"),
        ("velocity = [10.0, 10.0]", "velocity = [-10.0, 10.0]", "trajectory: leaves the tunnel"),
        (
            "start = [10.0, 14.8481]",
            'start = ["a", 1]',
            r"'trajectory.start\[0\]' must be a number",
        ),
        ("[tunnel]", "[tunnel", "not valid TOML"),
    ],
)
def test_malformed_toml_names_the_key(tmp_path, old, new, match):
    path = tmp_path / "bad.toml"
    text = GOOD.replace(old, new)
    assert text != GOOD
    path.write_text(text)
    with pytest.raises(ScenarioError, match=match):
        tk.load_scenario(str(path))


def test_reference_tables_load():
    rows = tk.reference.load("jiang2023_table2")
    assert (
        len(rows) == 12
        and rows[3]["algorithm"] == "UPF"
        and rows[3]["mean_m"] == pytest.approx(0.011)
    )
    assert {r["configuration"] for r in tk.reference.load("italiano2026_table1")} >= {
        "JAVELIN-L",
        "TeNFiLoc-L",
    }
    p90 = tk.reference.load("halili2022_p90")
    assert any(r["p90_m"] is None for r in p90)
    with pytest.raises(ValueError, match="name: unknown reference table"):
        tk.reference.load("nope")
