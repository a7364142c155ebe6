import json
import subprocess
import sys

import pytest

from tunnelkit.cli import main
from tunnelkit.reproduce import Report, run, targets


def test_reproduce_jiang_crlb_json(capsys):
    assert (
        main(["reproduce", "jiang-crlb", "--runs", "400", "--seed", "3", "--format", "json"]) == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["meta"]["runs"] == 400 and out["meta"]["seed"] == 3
    assert [r["sigma_theta_deg"] for r in out["rows"]] == [0.5, 1.0, 2.0]
    for r in out["rows"]:
        assert 0.85 < r["tswls_over_crlb"] < 1.2
        assert r["ls_over_crlb"] > 1.5


def test_same_seed_same_numbers():
    a = run("jiang-crlb", runs=100, seed=11).rows
    b = run("jiang-crlb", runs=100, seed=11).rows
    c = run("jiang-crlb", runs=100, seed=12).rows
    assert a == b and a != c


def test_table_format_and_errors(capsys):
    assert main(["reproduce", "jiang-crlb", "--runs", "50", "--no-progress"]) == 0
    assert "sqrt_crlb_m" in capsys.readouterr().out
    assert main(["reproduce", "jiang-crlb", "--runs", "0"]) == 2
    assert "runs: must be >= 1" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["reproduce", "no-such-target"])
    with pytest.raises(ValueError, match="name: unknown reproduce target"):
        run("no-such-target")


def test_registry_and_report_shapes():
    assert "jiang-crlb" in targets()
    rep = Report("t", ["a", "b"], [[1.0, float("nan")]])
    assert json.loads(rep.to_json())["rows"] == [{"a": 1.0, "b": None}]
    assert "-" in rep.to_table().splitlines()[-1]


def test_python_dash_m_entry_point():
    res = subprocess.run(
        [sys.executable, "-m", "tunnelkit", "scenarios"], capture_output=True, text=True, check=True
    )
    assert "jiang2023-straight" in res.stdout
