"""Two `make test` side by side on one machine both install Debian packages; they must wait for
each other instead of one failing on apt's lock. The Makefile's apt-get calls run under one flock:
here two `make chromium` run at once against a stand-in apt-get that records when it runs, and the
two installs must not overlap."""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

FAKE_APT = """#!/bin/sh
echo "start $$ $(date +%s.%N) $*" >> "$APT_LOG"
sleep 0.6
case "$*" in *install*) touch "$FAKE_CHROMIUM"; chmod +x "$FAKE_CHROMIUM";; esac
echo "end $$ $(date +%s.%N)" >> "$APT_LOG"
"""


@pytest.mark.skipif(
    sys.platform != "linux" or os.geteuid() != 0, reason="the recipe installs as root"
)
def test_two_makes_take_turns_at_apt(tmp_path):
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    fake = bin_dir / "apt-get"
    fake.write_text(FAKE_APT)
    fake.chmod(0o755)
    log = tmp_path / "apt.log"
    procs = []
    for i in range(2):
        chromium = tmp_path / f"chromium{i}"
        env = dict(
            os.environ,
            PATH=f"{bin_dir}:{os.environ['PATH']}",
            APT_LOG=str(log),
            FAKE_CHROMIUM=str(chromium),
        )
        cmd = ["make", "-s", "chromium", f"CHROMIUM={chromium}", f"APT_LOCK_FILE={tmp_path}/lock"]
        procs.append(
            subprocess.Popen(
                cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
            )
        )
    outs = [p.communicate(timeout=60)[0] for p in procs]
    assert all(p.returncode == 0 for p in procs), outs
    spans, open_ = [], {}
    for line in log.read_text().splitlines():
        kind, pid, t = line.split()[:3]
        if kind == "start":
            open_[pid] = float(t)
        else:
            spans.append((open_.pop(pid), float(t)))
    assert len(spans) == 4, log.read_text()  # update + install, twice
    spans.sort()
    for (_, end), (start, _) in itertools.pairwise(spans):
        assert start >= end, f"two apt-get runs overlapped: {spans}"
