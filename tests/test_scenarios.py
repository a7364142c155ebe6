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


# --- the schema -----------------------------------------------------------------------------------

from pathlib import Path  # noqa: E402

from tunnelkit import cli, schema, schemadoc  # noqa: E402
from tunnelkit import doppler_drive as drive  # noqa: E402
from tunnelkit import scenarios as S  # noqa: E402
from tunnelkit.schema import spec as schema_spec  # noqa: E402

PRESETS = Path(__file__).resolve().parent.parent / "data" / "scenarios"


def _text(name: str) -> str:
    return (PRESETS / f"{name}.toml").read_text()


def _load_text(tmp_path, text: str):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return tk.load_scenario(str(path))


JAV, USR, HAL = "italiano2026-straight", "example-rectangular-28ghz", "halili2022-drive"
JIANG_GOOD = GOOD + "[noise]\nlevels = [[0.5, 0.1], [1.0, 1.0]]\n"

# (base file, old, new, regex the ScenarioError must match: it names the key)
MALFORMED = [
    # the malformed files
    (
        JAV,
        "shape = [10, 10]",
        "shape = [0, 10]",
        r"'base_station\.arrays\[0\]\.shape\[0\]' must be >= 1",
    ),
    (JAV, "comb = 8 ", "comb = 0 ", r"'radio\.comb' must be >= 1"),
    (JAV, "fc = 5.9e9", "fc = -5.9e9", r"'radio\.fc' must be >= 1e\+08 Hz"),
    (
        JAV,
        "elevation_deg = -30.0",
        "elevation_deg = 200.0",
        r"arrays\[0\]\.elevation_deg' must be <= 90",
    ),
    (JAV, "fc = 5.9e9 ", "", r"missing key 'radio\.fc'"),
    (
        JAV,
        "noise_figure_db = 5.0",
        "noise_figure_db = nan",
        r"'radio\.noise_figure_db' must be finite",
    ),
    (
        JAV,
        "shape = [10, 10]",
        "shape = [10.5, 10]",
        r"'base_station\.arrays\[0\]\.shape\[0\]' must be an integer",
    ),
    (
        JAV,
        "bandwidth = 100e6",
        "bandwith = 100e6",
        r"unknown key 'radio\.bandwith'; did you mean 'radio\.bandwidth'",
    ),
    (
        JAV,
        "position = [0.0, 0.0, 4.8]",
        "position = [0.0, 0.0, 5.5]",
        r"'base_station\.position' \[0\.0, 0\.0, 5\.5\] lies outside",
    ),
    (
        JAV,
        "position = [0.0, 0.0, 4.8]",
        "position = [0.0, 5.0, 1.0]",
        r"'base_station\.position' .* lies outside",
    ),
    (
        JAV,
        "position = [0.0, 0.0, 4.8]",
        "position = [0.0, 0.0, -0.5]",
        r"'base_station\.position' .* lies outside",
    ),
    (
        JIANG_GOOD,
        "position = [0.0, 0.0]",
        "position = [-100.0, 100.0]",
        r"'base_station\.position' \[-100\.0, 100\.0\] lies outside the tunnel walls",
    ),
    (
        JAV,
        '"tunnelkit.propagation"]',
        '"tunnelkit.__main__"]',
        r"'requires' entries must be one of",
    ),
    # more: types, ranges, unknown keys and sections, placement
    (
        JAV,
        "tx_power_dbm = 23.0",
        "tx_power_dbm = true",
        r"'radio\.tx_power_dbm' must be a number, got True",
    ),
    (JAV, "speed = 13.89", 'speed = "fast"', r"'trajectory\.speed' must be a number"),
    (JAV, "n_symbols = 12", "n_symbols = 12.0", r"'radio\.n_symbols' must be an integer"),
    (JAV, "[radio]", "[radoi]", r"unknown key 'radoi'; did you mean 'radio'"),
    (
        JAV,
        'paper = "italiano2026"',
        'paper = "italiano2025"',
        r"'paper' must be one of .*did you mean 'italiano2026'",
    ),
    (JAV, "y = -2.5 ", "y = -6.0 ", r"trajectory: leaves the tunnel"),
    (JAV, "y = 4.6 ", "y = 5.5 ", r"tunnel\.plates\[0\]|sticks out"),
    (
        JAV,
        "inclination_deg = 55.0",
        "inclination_deg = 0.0",
        r"'tunnel\.plates\[0\]\.inclination_deg' must be > 0",
    ),
    (
        JAV,
        "shape = [10, 10]",
        "shape = [200, 200]",
        r"'base_station\.arrays\[0\]\.shape' \[200, 200\] has 40000 elements, more than 4096",
    ),
    (
        JAV,
        "shape = [10, 10]",
        "shape = [40, 40]",
        r"'base_station\.arrays\[0\]\.shape' .* outside the tunnel's cross-section",
    ),
    (
        _text(USR).replace("comb = 4 ", "comb = 1 "),
        "n_symbols = 12 ",
        "n_symbols = 1000 ",
        r"'base_station\.arrays\[0\]\.shape' \[8, 8\] x 3168 tones x 1000 symbols needs a 3\.0 GiB",
    ),
    (
        JAV,
        "shape = [10, 10]",
        "shape = [10, 10, 1]",
        r"'base_station\.arrays\[0\]\.shape' must have shape \(2,\)",
    ),
    (JAV, "n_facets = 12 ", "n_facets = 1000000 ", r"'tunnel\.n_facets' must be <= 360"),
    (JAV, "period = 0.1 ", "period = 1e-9 ", r"'trajectory\.period' .* more than"),
    (
        JIANG_GOOD,
        "walls = [[",
        "wall = [[",
        r"unknown key 'tunnel\.wall'; did you mean 'tunnel\.walls'",
    ),
    (JIANG_GOOD, "[0.5, 0.1]", "[nan, 0.1]", r"'noise\.levels\[0\]\[0\]' must be finite"),
    (JIANG_GOOD, "[0.5, 0.1]", "[200.0, 0.1]", r"'noise\.levels' angle sigmas must be <= 180"),
    (JIANG_GOOD, "[0.5, 0.1]", "[0.5, -0.1]", r"'noise\.levels\[0\]\[1\]' must be >= 0"),
    (
        USR,
        'kind = "rectangular"',
        'kind = "rectangle"',
        r"'tunnel\.kind' must be one of .*did you mean 'rectangular'",
    ),
    (
        USR,
        "tilt_deg = 20.0",
        "tilt_deg = 100.0",
        r"'base_station\.arrays\[0\]\.tilt_deg' must be <= 90",
    ),
    (
        USR,
        "height = 6.0 ",
        "height = 6.0\nwall_height = 3.0 ",
        r"'tunnel\.wall_height' is not a key of kind 'rectangular'",
    ),
    (USR, 'kind = "lane"', 'kind = "slalom"', r"missing key 'trajectory\.amplitude'"),
    (USR, 'name = "example', 'paper = "me"\nname = "example', r"'paper' must be one of"),
    (USR, 'name = "example', 'requires = ["os"]\nname = "example', r"unknown key 'requires'"),
    (
        USR,
        "position = [0.0, 0.0, 5.8]",
        "position = [0.0, 0.0, 6.0]",
        r"'base_station\.position' .* lies outside",
    ),
    (
        USR,
        "[[base_station.arrays]]",
        "[base_station.array]",
        r"unknown key 'base_station\.array'; did you mean 'base_station\.arrays'",
    ),
    (
        USR,
        "scs = 120e3",
        "scs = 240e3",
        r"'radio\.n_rb' 264 resource blocks at radio\.scs = 240000 Hz",
    ),
    (HAL, "tx_y = 4.5 ", "tx_y = 6.0 ", r"'transmitter\.tx_y' = 6 m lies outside"),
    (HAL, "rx_height = 2.0 ", "rx_height = 5.0 ", r"'vehicle\.rx_height' = 5 m lies outside"),
    (HAL, "outlier_prob = 0.02", "outlier_prob = 1.5", r"'errors\.outlier_prob' must be <= 1"),
    (HAL, "spacing = 0.8 ", "spacing = 1e-9 ", r"'vehicle\.spacing':? .* more than"),
    (HAL, "[gnss]", "[gnss]\nsigma = 1.0", r"unknown key 'gnss\.sigma'"),
    (
        HAL,
        "speed_amplitude = 1.0",
        "speed_amplitude = 30.0",
        r"'vehicle\.speed_amplitude': must be below speed",
    ),
    (
        HAL,
        "pass_time = 37.0",
        "pass_time = 60.0",
        r"'transmitter\.pass_time': must be within the drive",
    ),
]


@pytest.mark.parametrize(("base", "old", "new", "match"), MALFORMED)
def test_malformed_scenario_files_name_the_key(tmp_path, base, old, new, match):
    text = base if "\n" in base else _text(base)
    assert old in text, f"{old!r} not in {base}"
    with pytest.raises(S.ScenarioError, match=match) as err:
        _load_text(tmp_path, text.replace(old, new, 1))
    assert str(err.value).startswith("bad.toml: ")  # the file is named first


def test_every_preset_loads_and_is_validated():
    names = tk.list_scenarios()
    assert {"jiang2023-straight", "italiano2026-straight", HAL, USR} <= set(names)
    fams = {tk.load_scenario(n).family for n in names}
    assert fams == {"jiang2023", "italiano2026", "halili2022", "user"}
    assert all(err is None for _, err in S.check_all())


def test_presets_keep_their_meaning():
    sc = tk.load_scenario(JAV)
    # defaults filled in equal what the builders assumed before (n_facets 12, offset 0, slalom 0)
    assert sc.sections["tunnel"]["n_facets"] == 12
    assert sc.sections["trajectory"]["slalom_amplitude"] == 0.0
    assert "n_rb" not in sc.sections["radio"]
    assert drive.load_drive_config(HAL) == drive.DriveConfig()


def test_names_resolve_only_inside_the_data_directory(tmp_path):
    for bad in ("../../pyproject", "../scenarios/jiang2023-straight", "..", "/etc/passwd", ""):
        with pytest.raises((S.ScenarioError, TypeError), match="name"):
            tk.load_scenario(bad)
    # an explicit path must be an existing .toml file, and a scenario
    with pytest.raises(S.ScenarioError, match="no such scenario file"):
        tk.load_scenario(str(tmp_path / "missing.toml"))
    pyproject = PRESETS.parent.parent / "pyproject.toml"
    with pytest.raises(S.ScenarioError, match=r"pyproject\.toml: unknown key"):
        tk.load_scenario(pyproject)
    # a Path object works like a string path
    copy = tmp_path / "copy.toml"
    copy.write_text(_text("jiang2023-straight"))
    assert tk.load_scenario(copy).name == "jiang2023-straight"


def test_main_module_is_guarded():
    import importlib

    mod = importlib.import_module("tunnelkit.__main__")  # no SystemExit on import
    assert callable(mod.main)


def test_load_drive_config_refuses_other_families():
    with pytest.raises(S.ScenarioError, match="'jiang2023-straight' is a 'jiang2023' scenario"):
        drive.load_drive_config("jiang2023-straight")
    with pytest.raises(S.ScenarioError, match="not a Halili drive"):
        drive.load_drive_config(USR)


def test_with_values_revalidates():
    sc = tk.load_scenario(USR)
    s2 = S.with_values(sc, {"radio.fc": 5.9e9, "base_station.arrays[*].shape": [4, 4]})
    assert s2.get("radio.fc") == 5.9e9 and [a.M for a in s2.arrays()] == [16, 16]
    assert sc.get("radio.fc") == 28e9  # the original is untouched
    with pytest.raises(S.ScenarioError, match=r"'radio\.fc' must be >= 1e\+08 Hz"):
        S.with_values(sc, {"radio.fc": 0.0})
    with pytest.raises(S.ScenarioError, match="arrays has 2 tables"):
        S.with_values(sc, {"base_station.arrays[5].shape": [4, 4]})
    s3 = S.scenario_from_dict(sc.raw, "mine.toml")
    assert s3.sections == sc.sections and s3.path.name == "mine.toml"


# --- templates and the command line ----------------------------------------------------------------


@pytest.mark.parametrize("preset", [USR, JAV, "italiano2026-slalom", "jiang2023-curved", HAL])
def test_template_round_trip(tmp_path, preset):
    text = S.template("mine", preset)
    path = tmp_path / "mine.toml"
    path.write_text(text)
    sc, src = tk.load_scenario(path), tk.load_scenario(preset)
    assert sc.name == "mine"
    # every key line is preceded by its comment from the schema
    lines = text.splitlines()
    for i, ln in enumerate(lines):
        if ln and not ln.startswith(("#", "[")):
            assert lines[i - 1].startswith("# "), ln
    strip = ("name", "description")
    if src.family == "italiano2026":  # a JAVELIN preset becomes your own semicircular tunnel
        assert sc.family == "user"
        a, b = sc.tunnel(), src.tunnel()
        assert [f.name for f in a.surfaces] == [f.name for f in b.surfaces]
        for fa, fb in zip(a.surfaces, b.surfaces, strict=True):
            np.testing.assert_allclose(fa.corners(), fb.corners(), atol=1e-12)
        for aa, ab in zip(sc.arrays(), src.arrays(), strict=True):
            np.testing.assert_allclose(aa.world, ab.world, atol=1e-12)
        np.testing.assert_allclose(sc.trajectory().position, src.trajectory().position)
        assert {k: v for k, v in sc.sections["radio"].items() if k != "n_rb"} == src.sections[
            "radio"
        ]
    else:
        assert sc.family == src.family
        assert {k: v for k, v in sc.sections.items() if k not in strip} == {
            k: v for k, v in src.sections.items() if k not in strip
        }


def test_cli_validates_and_exits_nonzero(tmp_path, capsys):
    assert cli.main(["scenarios"]) == 0
    out = capsys.readouterr().out
    assert "example-rectangular-28ghz" in out and "[user]" in out
    bad = tmp_path / "bad.toml"
    bad.write_text(_text(JAV).replace("comb = 8 ", "comb = 0 "))
    assert cli.main(["scenarios", str(bad), "jiang2023-straight"]) == 1
    err = capsys.readouterr()
    assert "'radio.comb' must be >= 1" in err.err and "jiang2023-straight" in err.out
    assert cli.main(["scenarios", "../../pyproject"]) == 1
    assert "neither a preset name" in capsys.readouterr().err
    assert cli.main(["scenarios", "show", USR]) == 0
    assert '"n_rb": 264' in capsys.readouterr().out


def test_cli_new_writes_a_template_and_refuses_to_overwrite(tmp_path, capsys):
    args = ["scenarios", "new", "my-tunnel", "--from", JAV, "--out", str(tmp_path)]
    assert cli.main(args) == 0
    path = tmp_path / "my-tunnel.toml"
    assert tk.load_scenario(path).family == "user"
    before = path.read_text()
    assert cli.main(args) == 2
    assert "already exists" in capsys.readouterr().err and path.read_text() == before
    assert cli.main(["scenarios", "new", "../evil", "--out", str(tmp_path)]) == 2
    assert cli.main(["scenarios", "new", "x", "--out", str(tmp_path / "nope")]) == 2
    # the subprocess entry point exits non-zero on a malformed file too
    import subprocess
    import sys

    bad = tmp_path / "bad.toml"
    bad.write_text(_text(USR).replace("fc = 28e9", "fc = -1.0"))
    r = subprocess.run(
        [sys.executable, "-m", "tunnelkit", "scenarios", str(bad)], capture_output=True, text=True
    )
    assert r.returncode == 1 and "'radio.fc' must be >= 1e+08 Hz" in r.stderr


def test_schema_documentation_is_current():
    """data/scenarios/README.md holds the tables generated from the spec."""
    readme = (PRESETS / "README.md").read_text()
    assert schemadoc.to_markdown() in readme


def test_every_key_has_a_doc_and_sane_spec():
    def walk(table, path):
        for k in table.keys + tuple(x for ks in table.variants.values() for x in ks):
            assert k.doc and k.type in (
                "float",
                "int",
                "str",
                "floats",
                "ints",
                "strs",
                "table",
                "tables",
            ), path + k.name
            if k.table is not None:
                walk(k.table, path + k.name + ".")
            if k.has_default and k.type in ("float", "int"):
                schema_spec._check_number("spec", path + k.name, k, k.default, k.type == "int")

    for fam in schema.FAMILIES.values():
        walk(fam, "")


def test_symlink_out_of_the_data_directory_is_refused(tmp_path, monkeypatch):
    (tmp_path / "scenarios").mkdir()
    outside = tmp_path / "outside.toml"
    outside.write_text(_text("jiang2023-straight"))
    (tmp_path / "scenarios" / "evil.toml").symlink_to(outside)
    (tmp_path / "scenarios" / "good.toml").write_text(_text("jiang2023-straight"))
    monkeypatch.setenv("TUNNELKIT_DATA", str(tmp_path))
    assert tk.load_scenario("good").name == "jiang2023-straight"
    with pytest.raises(S.ScenarioError, match="unknown scenario 'evil'"):
        tk.load_scenario("evil")


# --- property: any mutation of a valid file loads or raises ScenarioError, nothing else --------------

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_VALUES = [
    None,
    0,
    -1,
    1,
    2.5,
    10.5,
    -1e30,
    1e30,
    float("nan"),
    float("inf"),
    True,
    "x",
    [],
    [1, 2],
    [0.0, 0.0, 0.0],
    [[1.0, 2.0]],
    {},
    {"a": 1},
]


def _leaves(tab, path=()):
    for k, v in tab.items():
        if isinstance(v, dict):
            yield from _leaves(v, (*path, k))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for i, x in enumerate(v):
                yield from _leaves(x, (*path, k, i))
        else:
            yield (*path, k)


_RAWS = {n: tk.load_scenario(n).raw for n in (JAV, USR, HAL, "jiang2023-curved")}


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(sorted(_RAWS)),
    picks=st.lists(
        st.tuples(st.integers(0, 10**6), st.sampled_from(_VALUES)), min_size=1, max_size=3
    ),
)
def test_mutated_files_load_or_raise_scenario_error(name, picks):
    import copy

    raw = copy.deepcopy(_RAWS[name])
    leaves = list(_leaves(raw))
    for idx, value in picks:
        *parents, last = leaves[idx % len(leaves)]
        tab = raw
        for p in parents:
            tab = tab[p]
        if value is None:
            tab.pop(last, None)
        else:
            tab[last] = copy.deepcopy(value)
    try:
        sc = S.scenario_from_dict(raw, "mutant.toml")
    except S.ScenarioError as exc:
        assert str(exc).startswith("mutant.toml: ")
        return
    # what loads is usable: tunnel, trajectory (and arrays/radio) build without error
    if sc.family == "halili2022":
        assert isinstance(
            drive.DriveConfig(
                **{k: v for t in sc.sections.values() if isinstance(t, dict) for k, v in t.items()}
            ),
            drive.DriveConfig,
        )
        return
    tun = sc.tunnel()
    tr = sc.trajectory(tun)
    assert np.all(np.isfinite(tr.position))
    if sc.family in ("user", "italiano2026"):
        assert all(np.all(np.isfinite(a.world)) for a in sc.arrays())
