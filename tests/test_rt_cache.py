"""The ray-tracing cache never trusts what it reads: a truncated, foreign or non-finite epoch
file is traced again (named in a warning), a label is a plain name, a directory that resolves
outside the cache is refused, and a rebuild removes the cache's own files only.

No Sionna needed: the trace is replaced by a small synthetic one (two paths per element)."""

from __future__ import annotations

import json
import os
import warnings

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import channel, propagation, rt
from tunnelkit.rt.elements import ElementPaths


@pytest.fixture(scope="module")
def drive():
    sc = tk.load_scenario("italiano2026-straight")
    tun, cfg = sc.tunnel(), channel.SRSConfig.from_scenario(sc)
    return tun, propagation.scenario_arrays(sc), sc.trajectory(tun), cfg


def _channel(drive, tmp_path, label="t"):
    """A channel whose trace is synthetic and counted."""
    tun, arrays, traj, cfg = drive
    rc = rt.RayTracedChannel(tun, arrays, traj, cfg, label=label, cache_dir=tmp_path)
    arr = arrays[1]
    M = len(arr.world)
    rc.traced = 0

    def trace(k, tunnel=None):
        rc.traced += 1
        tau = np.tile([50e-9, 80e-9], (M, 1)) + 1e-12 * np.arange(M)[:, None]
        ep = ElementPaths(
            tau,
            np.full((M, 2), 1e-4 + 0j),
            np.zeros((M, 2)),
            np.ones((M, 2), bool),
            np.tile([0, 1], (M, 1)),
            np.zeros((M, 2), bool),
            np.zeros((M, 2), np.int64),
        )
        return arr, ep, 0.01

    rc.trace = trace
    return rc


def test_a_good_file_is_read_back_without_tracing(drive, tmp_path):
    first = _channel(drive, tmp_path)
    e = first.epoch(3)
    assert first.traced == 1 and e["array"] == "+x" and np.all(np.isfinite(e["H"]))
    again = _channel(drive, tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(again.epoch(3)["H"], e["H"])
    assert again.traced == 0


def _rewrite(f, **change):
    with np.load(f) as z:
        d = {k: z[k] for k in z.files}
    d.update(change)
    for k in [k for k, v in change.items() if v is None]:
        del d[k]
    np.savez(f, **d)


@pytest.mark.parametrize(
    ("spoil", "why"),
    [
        (lambda f: f.write_bytes(f.read_bytes()[:200]), "BadZipFile|EOFError|OSError"),
        (lambda f: f.write_bytes(b""), "Error"),
        (lambda f: _rewrite(f, H=None), "missing H"),
        (lambda f: _rewrite(f, H=np.full((100, 410, 12), np.nan + 0j)), "H: not finite"),
        (lambda f: _rewrite(f, H=np.zeros((100, 4, 12), complex)), "H: expected complex"),
        (lambda f: _rewrite(f, array=np.array("elsewhere")), "none of this drive's"),
        (lambda f: _rewrite(f, los_valid=np.ones(3, bool)), "los_valid"),
        (lambda f: _rewrite(f, power_json=np.array("{")), "JSONDecodeError"),
        (lambda f: _rewrite(f, count_json=np.array(json.dumps({"los": 1}))), "count: expected"),
    ],
)
def test_a_bad_file_is_named_and_traced_again(drive, tmp_path, spoil, why):
    first = _channel(drive, tmp_path)
    good = first.epoch(5)["H"]
    f = first.directory() / "epoch-005.npz"
    spoil(f)
    again = _channel(drive, tmp_path)
    with pytest.warns(UserWarning, match=rf"epoch-005\.npz is unreadable \(.*({why})"):
        e = again.epoch(5)
    assert again.traced == 1
    np.testing.assert_array_equal(e["H"], good)


def test_a_file_still_bad_after_tracing_is_refused_by_name(drive, tmp_path):
    rc = _channel(drive, tmp_path)
    real = rc._store

    def store_nan(k, tunnel, f):
        real(k, tunnel, f)
        _rewrite(f, los_tau=np.full(100, np.inf))

    rc._store = store_nan
    with pytest.warns(UserWarning, match="unreadable"):
        with pytest.raises(ValueError, match=r"epoch-002\.npz traced again is still bad"):
            rc.epoch(2)


@pytest.mark.parametrize(
    "label", ["..", ".", "../x", "/etc", "a/b", "", ".hidden", "a\\b", "x" * 101]
)
def test_a_label_is_a_plain_name(drive, tmp_path, label):
    tun, arrays, traj, cfg = drive
    with pytest.raises(ValueError, match="label: expected a plain name"):
        rt.RayTracedChannel(tun, arrays, traj, cfg, label=label, cache_dir=tmp_path)


def test_a_directory_linked_out_of_the_cache_is_refused(drive, tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.txt").write_text("not the cache's")
    cache = tmp_path / "cache"
    cache.mkdir()
    os.symlink(outside, cache / "t")
    rc = _channel(drive, cache)
    with pytest.raises(ValueError, match="outside the cache"):
        rc.directory()
    assert (outside / "keep.txt").read_text() == "not the cache's"


def test_a_rebuild_removes_the_cache_files_only(drive, tmp_path):
    rc = _channel(drive, tmp_path)
    d = rc.directory()
    rc.epoch(1)
    (d / "notes.txt").write_text("mine")
    outside = tmp_path / "precious.npz"
    outside.write_bytes(b"data")
    os.symlink(outside, d / "epoch-999.npz")
    meta = json.loads((d / "meta.json").read_text())
    meta["scene"] = "0" * 64
    (d / "meta.json").write_text(json.dumps(meta))
    other = _channel(drive, tmp_path)
    with pytest.warns(UserWarning, match="another scene"):
        assert other.directory() == d
    assert not (d / "epoch-001.npz").exists() and not (d / "epoch-999.npz").is_symlink()
    assert (d / "notes.txt").read_text() == "mine" and outside.read_bytes() == b"data"
