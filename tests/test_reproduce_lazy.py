"""``tunnelkit.reproduce.run`` imports only its target's module: notebook 01's ``jiang-crlb``
loads neither the drive simulator nor the ray tracer."""

from __future__ import annotations

import subprocess
import sys

import tunnelkit.reproduce as rep


def test_the_module_map_is_the_registry():
    reg = rep.targets()
    assert set(rep.TARGET_MODULES) == set(reg)
    for name, t in reg.items():
        assert t.fn.__module__ == f"tunnelkit.reproduce.{rep.TARGET_MODULES[name]}", name


def test_jiang_crlb_loads_no_drive_simulator_or_ray_tracer():
    code = (
        "import sys, tunnelkit as tk\n"
        "tk.reproduce.run('jiang-crlb', runs=20, seed=0)\n"
        "print(sorted(m for m in ('tunnelkit.simulation', 'tunnelkit.rt', 'tunnelkit.design')"
        " if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]", out.stdout
