"""Mitsuba export/import of tunnels and the engine switch's bad-input behaviour (tunnelkit.rt)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

import tunnelkit as tk
from tunnelkit import propagation, rt


@pytest.fixture(scope="module")
def javelin():
    sc = tk.load_scenario("italiano2026-straight")
    return sc, sc.tunnel()


def read_ply(path: Path) -> tuple[np.ndarray, np.ndarray]:
    lines = path.read_text().splitlines()
    nv = int(next(ln for ln in lines if ln.startswith("element vertex")).split()[-1])
    start = lines.index("end_header") + 1
    v = np.array([[float(x) for x in ln.split()] for ln in lines[start : start + nv]])
    f = np.array([[int(x) for x in ln.split()[1:]] for ln in lines[start + nv :]])
    return v, f


def test_export_one_ply_per_surface_exact_geometry(javelin, tmp_path):
    _, tun = javelin
    ms = rt.export_tunnel(tun, tmp_path, name="javelin")
    assert ms.xml == tmp_path / "javelin.xml"
    assert ms.n_surfaces == len(tun.surfaces) == 12 + 1 + 4
    assert len(list((tmp_path / "meshes").glob("*.ply"))) == ms.n_surfaces
    root = ET.parse(ms.xml).getroot()
    mats = {b.get("id"): b.find("string").get("value") for b in root.iter("bsdf")}
    assert sorted(mats.values()) == ["concrete", "metal"]
    for shape, surf in zip(root.iter("shape"), tun.surfaces, strict=True):
        info = ms.surfaces[shape.get("id")]
        assert (info.name, info.kind) == (surf.name, surf.kind)
        assert mats[shape.find("ref").get("id")] == ("metal" if surf.kind == "rrm" else "concrete")
        v, f = read_ply(tmp_path / shape.find("string").get("value"))
        np.testing.assert_array_equal(v, surf.corners())  # repr() round-trips float64 exactly
        for tri in f:  # winding: geometric normal = the facet's inward normal
            n = np.cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]])
            assert n @ surf.normal > 0.99 * np.linalg.norm(n)


def test_export_blockers_as_boxes(javelin, tmp_path):
    _, tun = javelin
    ms = rt.export_tunnel(tun.with_blockers(propagation.truck_box(20.0, -2.5)), tmp_path)
    kinds = [s.kind for s in ms.surfaces.values()]
    assert kinds.count("blocker") == 1 and len(kinds) == 18
    v, f = read_ply(tmp_path / "meshes" / "truck.ply")
    assert v.shape == (8, 3) and f.shape == (12, 3)
    centre = v.mean(axis=0)
    for tri in f:  # outward winding
        n = np.cross(v[tri[1]] - v[tri[0]], v[tri[2]] - v[tri[0]])
        assert n @ (v[tri].mean(axis=0) - centre) > 0


def test_export_bad_input(javelin, tmp_path):
    _, tun = javelin
    with pytest.raises(TypeError, match="tunnel"):
        rt.export_tunnel("tunnel", tmp_path)
    with pytest.raises(ValueError, match="name"):
        rt.export_tunnel(tun, tmp_path, name="../evil")


def test_read_scene_roundtrip_and_errors(javelin, tmp_path):
    _, tun = javelin
    ms = rt.export_tunnel(tun, tmp_path)
    back = rt.read_scene(ms.xml)
    assert list(back.surfaces) == list(ms.surfaces)
    assert back.surfaces["rrm-top-left"].kind == "rrm"
    assert back.surfaces["facet-0"].kind == "surface"  # a user scene: role unknown from "facet"
    with pytest.raises(rt.SceneError, match="does not exist"):
        rt.read_scene(tmp_path / "missing.xml")
    bad = tmp_path / "bad.xml"
    bad.write_text("<scene version='2.1.0'><shape type='ply'></scene>")
    with pytest.raises(rt.SceneError, match="does not parse"):
        rt.read_scene(bad)
    empty = tmp_path / "empty.xml"
    empty.write_text("<scene version='2.1.0'><bsdf type='diffuse' id='x'/></scene>")
    with pytest.raises(rt.SceneError, match="no <shape>"):
        rt.read_scene(empty)
    notscene = tmp_path / "other.xml"
    notscene.write_text("<html/>")
    with pytest.raises(ValueError, match="expected <scene>"):
        rt.read_scene(notscene)


def test_compute_paths_image_engine_is_trace_paths(javelin):
    sc, tun = javelin
    arr = propagation.scenario_arrays(sc)[1]
    ue, v = [30.0, -2.5, 1.5], [-13.89, 0.0, 0.0]
    a = rt.compute_paths(tun, arr, ue, v, fc=5.9e9)
    b = propagation.trace_paths(tun, arr, ue, v, fc=5.9e9)
    assert [(p.surface, p.length) for p in a] == [(p.surface, p.length) for p in b]
    with pytest.raises(ValueError, match="engine"):
        rt.compute_paths(tun, arr, ue, v, fc=5.9e9, engine="raytracer")
    with pytest.raises(TypeError, match="no options"):
        rt.compute_paths(tun, arr, ue, v, fc=5.9e9, samples_per_src=10)


def test_missing_extra_says_how_to_install(monkeypatch):
    monkeypatch.setattr(rt, "_checked", False)
    monkeypatch.setitem(sys.modules, "drjit", None)  # "not installed"
    with pytest.raises(ImportError, match=r"pip install -e '\.\[rt\]'"):
        rt.require_sionna()
    assert not rt.sionna_available()


def test_old_llvm_is_an_error_not_an_abort(monkeypatch):
    dr = pytest.importorskip("drjit")  # the extra is installed in CI (see test_rt_crossval)
    monkeypatch.setattr(rt, "_checked", False)
    monkeypatch.setattr(dr.detail, "llvm_version", lambda: (15, 0, 6))
    with pytest.raises(rt.RTUnavailableError, match=r"LLVM 15\.0\.6 .*need >= 17.*libllvm19"):
        rt.require_sionna()


LIBDIR = Path("/usr/lib/x86_64-linux-gnu")


@pytest.mark.parametrize(
    ("lib", "expect"),
    [("libLLVM-15.so.1", "LLVM 15"), ("libLLVM-14.so.1", "no usable LLVM|did not initialise")],
)
def test_real_old_llvm_in_a_subprocess(lib, expect):
    """With Debian's LLVM 15 (which aborts Sionna's first solve) or 14 (too old for Dr.Jit, whose
    initialisation then sometimes hangs) the process ends with our error and exit code 0, not an
    LLVM abort or a hang."""
    pytest.importorskip("drjit")
    if not (LIBDIR / lib).is_file():
        pytest.skip(f"{lib} not installed")
    code = (
        "from tunnelkit import rt\n"
        "rt.PROBE_TIMEOUT = 15\n"
        "try:\n    rt.require_sionna()\nexcept rt.RTUnavailableError as e:\n    print('ERR', e)\n"
    )
    env = dict(os.environ, DRJIT_LIBLLVM_PATH=str(LIBDIR / lib))
    out = subprocess.run(
        [sys.executable, "-c", code],
        env=env,
        capture_output=True,
        text=True,
        timeout=90,
        stdin=subprocess.DEVNULL,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("ERR") and re.search(expect, out.stdout), out.stdout


def test_sionna_rejects_unloadable_scenes(tmp_path):
    rt.require_sionna()
    from tunnelkit.rt.sionna_engine import SionnaEngine, load_sionna_scene

    xml = tmp_path / "nomesh.xml"
    xml.write_text(
        "<scene version='2.1.0'><bsdf type='itu-radio-material' id='m'>"
        "<string name='type' value='concrete'/></bsdf>"
        "<shape type='ply' id='wall-1'><string name='filename' value='meshes/none.ply'/>"
        "<ref id='m' name='bsdf'/></shape></scene>"
    )
    with pytest.raises(rt.SceneError, match="could not be loaded"):
        load_sionna_scene(xml, fc=5.9e9)
    with pytest.raises(rt.SceneError, match="no <shape>"):
        empty = tmp_path / "empty.xml"
        empty.write_text("<scene version='2.1.0'/>")
        SionnaEngine(empty, fc=5.9e9)
    with pytest.raises(TypeError, match="tunnel"):
        SionnaEngine(42, fc=5.9e9)
