"""The benchmark runner tells timed benchmarks from study scripts and loads only the former."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _runner():
    spec = importlib.util.spec_from_file_location("bench_runner", ROOT / "benchmarks" / "run.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["bench_runner"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_a_study_script_is_listed_and_not_imported(tmp_path):
    run = _runner()
    (tmp_path / "bench_timed.py").write_text("def cases():\n    return []\n")
    # importing this file would raise: the runner must not import a study script
    (tmp_path / "bench_study.py").write_text("raise SystemExit('imported')\n")
    assert run.study_scripts(tmp_path) == ["bench_study.py"]
    assert run._load_cases(None, tmp_path) == []


def test_every_benchmark_is_timed_or_a_runnable_study_script():
    run = _runner()
    for path in sorted((ROOT / "benchmarks").glob("bench_*.py")):
        if run.is_timed(path):
            continue
        text = path.read_text(encoding="utf-8")
        assert 'if __name__ == "__main__"' in text, f"{path.name}: neither cases() nor a main"
