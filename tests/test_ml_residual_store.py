"""The stored noise-only calibrations of the residual test (``residual.STORE``): used only where
they reproduce, and what a fresh calibration gives."""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from tunnelkit import arrays
from tunnelkit.constants import C
from tunnelkit.extraction.ml import residual
from tunnelkit.scenarios import data_dir

FC = 5.9e9
LAM = C / FC
ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    """Empty per-process caches, the data folder a temporary one (restored afterwards)."""
    monkeypatch.setattr(residual, "_NULL_CACHE", {})
    monkeypatch.setattr(residual, "_STORED", {})
    monkeypatch.setenv("TUNNELKIT_DATA", str(tmp_path))
    return tmp_path / residual.STORE


def _forbid_calibration(monkeypatch):
    def fail(*a, **k):
        raise AssertionError("calibrated although a valid stored calibration exists")

    monkeypatch.setattr(residual, "peak_null", fail)


def test_a_stored_calibration_is_used_only_where_its_first_draw_reproduces(fresh, monkeypatch):
    pos, shape = arrays.ura(2, 2, LAM / 2), (4, 16, 4)
    thr = residual.calibrated_threshold(pos, FC, shape)  # no store: calibrated
    rec = residual.calibration_store()
    assert rec["settings"] == {"draws": residual.CALIBRATION_DRAWS, "n_cells": 8,
                               "seed": residual.CALIBRATION_SEED, "tail_share": 0.25}  # fmt: skip
    (entry,) = rec["entries"]
    assert entry["shape"] == list(shape) and entry["fc"] == FC and entry["M"] == 4
    fresh.parent.mkdir(parents=True)
    fresh.write_text(json.dumps(rec))
    # read back in a new process (empty caches): the same threshold, no calibration run
    monkeypatch.setattr(residual, "_NULL_CACHE", {})
    monkeypatch.setattr(residual, "_STORED", {})
    real = residual.peak_null
    _forbid_calibration(monkeypatch)
    assert residual.calibrated_threshold(pos, FC, shape) == thr
    # a stored entry whose first draw does not reproduce, of other settings, of another array,
    # carrier or shape: not used, the calibration runs (and gives the threshold above)
    monkeypatch.setattr(residual, "peak_null", real)
    for bad in ({**rec, "entries": [{**entry, "first_peak": entry["first_peak"] * (1 + 1e-15)}]},
                {**rec, "settings": {**rec["settings"], "draws": 100}}):  # fmt: skip
        bad["entries"][0]["x_q"] = 1e3  # a threshold that would show if it were read
        fresh.write_text(json.dumps(bad))
        monkeypatch.setattr(residual, "_NULL_CACHE", {})
        monkeypatch.setattr(residual, "_STORED", {})
        assert residual.calibrated_threshold(pos, FC, shape) == thr
    fresh.write_text(json.dumps(rec))
    for args in ((pos * 1.01, FC, shape), (pos, 1.01 * FC, shape), (pos, FC, (4, 16, 5))):
        monkeypatch.setattr(residual, "_NULL_CACHE", {})
        monkeypatch.setattr(residual, "_STORED", {})
        assert residual._stored_law(*args) is None, args


def test_the_shipped_store_is_what_a_fresh_calibration_gives(monkeypatch):
    """The paper tunnel's 4 x 4 (one of the tool's cases; ``tools/residual_null.py --check``
    re-measures them all) calibrated afresh gives its stored entry (bit for bit on the machine
    that wrote it; within float rounding, 1e-12, on another CPU or BLAS: measured 3e-15), and is
    read back."""
    stored = json.loads((data_dir() / residual.STORE).read_text())
    spec = importlib.util.spec_from_file_location(
        "residual_null", ROOT / "tools" / "residual_null.py"
    )
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    monkeypatch.setattr(residual, "_NULL_CACHE", {})
    monkeypatch.setattr(residual, "_STORED", {})
    rec = tool.measure([("italiano2026-straight", "4x4")])
    (entry,) = rec["entries"]
    assert stored["settings"] == rec["settings"]
    law = ("x_q", "s")
    same = [e for e in stored["entries"] if {k: v for k, v in e.items() if k not in law}
            == {k: v for k, v in entry.items() if k not in law}]  # fmt: skip
    assert len(same) == 1
    for k in law:
        assert entry[k] == pytest.approx(same[0][k], rel=1e-12, abs=0), k
    assert {e["M"] for e in stored["entries"]} == {16, 36, 100}  # the tool's three cases
    # the 4 x 4's entry is read back (checked against its first draw) without calibrating
    x_q, s, pos, fc, shape = next(iter(residual._NULL_CACHE.values()))
    monkeypatch.setattr(residual, "_NULL_CACHE", {})
    monkeypatch.setattr(residual, "_STORED", {})
    _forbid_calibration(monkeypatch)
    assert residual._stored_law(pos, fc, shape) == pytest.approx((x_q, s), rel=1e-12, abs=0)
    assert np.isfinite(residual.calibrated_threshold(pos, fc, shape))
