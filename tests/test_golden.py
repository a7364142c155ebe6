"""The golden regression of the command line still holds on its fastest cases (the whole set:
``python benchmarks/golden.py --compare benchmarks/golden``, a few minutes)."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_jiang_crlb_json_is_byte_identical_to_the_golden_files():
    out = subprocess.run(
        [
            sys.executable,
            "benchmarks/golden.py",
            "--compare",
            "benchmarks/golden",
            "--only",
            "jiang-crlb",
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    assert out.stdout.count("identical jiang-crlb") == 2
