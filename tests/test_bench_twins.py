"""``bench_ml.TWINS`` names every module whose fits call the numerics' unchecked twins, and only
those (``bench_stress --cpu`` and ``bench_ml``'s check share swap them for the checked functions;
a twin that moved modules broke them)."""

import importlib
import pkgutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))

import bench_ml

import tunnelkit.extraction as ex
from tunnelkit.extraction import linalg, numerics


def test_twins_lists_every_module_holding_an_unchecked_twin():
    held = {}
    for info in pkgutil.walk_packages(ex.__path__, "tunnelkit.extraction."):
        m = importlib.import_module(info.name)
        names = {
            k.removesuffix("_unchecked")
            for k, v in vars(m).items()
            if k.endswith("_unchecked") and getattr(numerics, k, None) is v
        }
        if names and m not in (numerics, linalg):  # the twins and their checked forms
            held[m.__name__] = names
    assert {k: set(v) for k, v in bench_ml.TWINS.items()} == held
    ran = bench_ml.checked_numerics(lambda: "done")
    assert ran == "done"
    for mod, names in bench_ml.TWINS.items():  # swapped back
        m = importlib.import_module(mod)
        for n in names:
            assert getattr(m, f"{n}_unchecked") is getattr(numerics, f"{n}_unchecked")
