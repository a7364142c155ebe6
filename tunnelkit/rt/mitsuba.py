"""Mitsuba 3 scenes for Sionna RT: export a tunnelkit tunnel, load a user's (Blender) scene.

Export writes one PLY mesh per surface (every tunnel facet, the road, every road-marking plate and
every blocker box) and a Mitsuba XML that gives each shape an ITU-R P.2040 radio material
(``itu-radio-material``: "concrete" for the tunnel shell, "metal" for the RRMs and blockers). The
scene must be loaded with ``merge_shapes=False`` so that a Sionna path still names the surface it
bounced off; :class:`MitsubaScene` keeps the map from shape id to the tunnelkit surface.

Writing the files needs numpy only; loading them needs the ``rt`` extra (Sionna RT).

    >>> from tunnelkit.rt import export_tunnel
    >>> ms = export_tunnel(sc.tunnel(), "build/rt/javelin")     # doctest: +SKIP
    >>> ms.xml, ms.surfaces["facet-0"]                          # doctest: +SKIP
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path as FsPath

import numpy as np

from .._validate import instance, record
from ..propagation import Box, Facet, Tunnel3D

__all__ = ["MitsubaScene", "SceneError", "SurfaceInfo", "export_tunnel", "read_scene"]

#: ITU-R P.2040 material name and slab thickness [m] for each tunnelkit material.
ITU_MATERIALS: dict[str, tuple[str, float]] = {
    "concrete": ("concrete", 0.3),
    "metal": ("metal", 0.01),
}


class SceneError(ValueError):
    """A Mitsuba scene that cannot be used: missing file, does not parse, no surfaces."""


@dataclass(frozen=True)
class SurfaceInfo:
    """What a shape of the Mitsuba scene stands for.

    ``name`` is the tunnelkit surface name ("facet 3", "road", "RRM top left") or the shape id of a
    user scene; ``kind`` is "wall", "ceiling", "road", "rrm", "blocker" or "surface" (a user shape
    of unknown role); ``material`` the ITU material name.
    """

    name: str
    kind: str
    material: str

    def __post_init__(self) -> None:  # a user shape may name no material
        record(self, may_be_empty=("material",))


@dataclass(frozen=True)
class MitsubaScene:
    """A Mitsuba XML scene on disk and the tunnelkit meaning of its shapes (by shape id)."""

    xml: FsPath
    surfaces: dict[str, SurfaceInfo] = field(default_factory=dict)

    def __post_init__(self) -> None:
        instance("xml", self.xml, FsPath)
        for k, v in dict(instance("surfaces", self.surfaces, dict)).items():
            instance(f"surfaces[{k!r}]", v, SurfaceInfo)

    @property
    def n_surfaces(self) -> int:
        """Number of shapes."""
        return len(self.surfaces)


def _shape_id(name: str, used: set[str]) -> str:
    base = re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-") or "surface"
    sid, k = base, 1
    while sid in used:
        k += 1
        sid = f"{base}-{k}"
    used.add(sid)
    return sid


def _write_ply(path: FsPath, vertices: np.ndarray, faces: np.ndarray) -> None:
    """ASCII PLY with float64 vertices (no rounding of the geometry) and triangle faces."""
    lines = [
        "ply",
        "format ascii 1.0",
        f"element vertex {len(vertices)}",
        "property double x",
        "property double y",
        "property double z",
        f"element face {len(faces)}",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    lines += [" ".join(repr(float(c)) for c in v) for v in vertices]
    lines += ["3 " + " ".join(str(int(i)) for i in f) for f in faces]
    path.write_text("\n".join(lines) + "\n")


def facet_mesh(facet: Facet) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (4, 3) and two triangles (2, 3) of a rectangle, wound so ``facet.normal`` is the
    geometric normal (counter-clockwise seen from the inside of the tunnel)."""
    v = facet.corners()
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    n = np.cross(v[1] - v[0], v[2] - v[0])
    if n @ facet.normal < 0:
        tri = tri[:, ::-1]
    return v, tri


def box_mesh(box: Box) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (8, 3) and 12 outward-wound triangles of an axis-aligned box."""
    lo, hi = box.lo, box.hi
    v = np.array(
        [
            [hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1], hi[2] if i & 4 else lo[2]]
            for i in range(8)
        ]
    )
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tri = []
    for a, b, c, d in quads:
        tri += [[a, b, c], [a, c, d]]
    return v, np.array(tri)


def export_tunnel(tunnel: Tunnel3D, directory, *, name: str = "tunnel") -> MitsubaScene:
    """Write ``tunnel`` as ``<directory>/<name>.xml`` plus ``<directory>/meshes/*.ply``.

    One PLY per facet, road, RRM plate and blocker box; each shape references an
    ``itu-radio-material`` bsdf (ITU-R P.2040 "concrete" or "metal"). Returns the XML path and the
    shape-id -> surface map. Load the result with ``merge_shapes=False`` (as
    :func:`tunnelkit.rt.sionna_engine.load_sionna_scene` does).
    """
    if not isinstance(tunnel, Tunnel3D):
        raise TypeError(f"tunnel: expected a propagation.Tunnel3D, got {type(tunnel).__name__}")
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_.-]+", name):
        raise ValueError(f"name: expected a plain file stem (letters, digits, _.-), got {name!r}")
    out = FsPath(instance("directory", directory, (str, PathLike), "a directory name"))
    if not str(directory) or "\0" in str(directory):
        raise ValueError(f"directory: expected a directory name, got {str(directory)!r}")
    (out / "meshes").mkdir(parents=True, exist_ok=True)
    root = ET.Element("scene", version="2.1.0")
    used_mat: set[str] = set()
    surfaces: dict[str, SurfaceInfo] = {}
    used_ids: set[str] = set()

    def add_shape(label: str, kind: str, material: str, verts, tri) -> None:
        itu, thickness = ITU_MATERIALS[material]
        mat_id = f"mat-itu-{itu}"
        if mat_id not in used_mat:
            used_mat.add(mat_id)
            b = ET.Element("bsdf", type="itu-radio-material", id=mat_id)
            ET.SubElement(b, "string", name="type", value=itu)
            ET.SubElement(b, "float", name="thickness", value=repr(thickness))
            root.insert(len(used_mat) - 1, b)
        sid = _shape_id(label, used_ids)
        _write_ply(out / "meshes" / f"{sid}.ply", verts, tri)
        s = ET.SubElement(root, "shape", type="ply", id=sid)
        ET.SubElement(s, "string", name="filename", value=f"meshes/{sid}.ply")
        ET.SubElement(s, "boolean", name="face_normals", value="true")
        ET.SubElement(s, "ref", id=mat_id, name="bsdf")
        surfaces[sid] = SurfaceInfo(label, kind, itu)

    for f in tunnel.surfaces:
        add_shape(f.name or f.kind, f.kind, f.material, *facet_mesh(f))
    for b in tunnel.blockers:
        add_shape(b.name, "blocker", "metal", *box_mesh(b))
    ET.indent(root)
    xml = out / f"{name}.xml"
    xml.write_text(ET.tostring(root, encoding="unicode") + "\n")
    return MitsubaScene(xml, surfaces)


_KINDS = ("wall", "ceiling", "road", "rrm", "blocker")


def read_scene(path) -> MitsubaScene:
    """Parse a user's Mitsuba XML (e.g. exported from Blender with the Mitsuba add-on).

    Checks that the file exists, is well-formed XML with a ``<scene>`` root and declares at least
    one ``<shape>`` with an id; raises :class:`SceneError` (a ``ValueError``) naming the file
    otherwise. A shape's kind is taken from its id when the id starts with one of "wall",
    "ceiling", "road", "rrm", "blocker" (so ``rrm-left`` is an RRM), otherwise "surface". Mesh
    files are resolved by Mitsuba when the scene is loaded.
    """
    p = FsPath(instance("path", path, (str, PathLike), "a file name"))
    if not p.is_file():
        raise SceneError(f"scene file {str(p)!r} does not exist")
    try:
        root = ET.parse(p).getroot()
    except ET.ParseError as exc:
        raise SceneError(f"scene file {str(p)!r} does not parse as XML: {exc}") from None
    if root.tag != "scene":
        raise SceneError(f"scene file {str(p)!r}: root element is <{root.tag}>, expected <scene>")
    mats: dict[str, str] = {}
    for b in root.iter("bsdf"):
        t = next((s.get("value") for s in b.iter("string") if s.get("name") == "type"), "")
        mats[b.get("id", "")] = t or b.get("type", "")
    surfaces: dict[str, SurfaceInfo] = {}
    for i, s in enumerate(root.iter("shape")):
        sid = s.get("id") or f"shape-{i}"
        ref = next((r.get("id") for r in s.iter("ref")), "")
        low = sid.lower()
        kind = next((k for k in _KINDS if low.startswith(k)), "surface")
        surfaces[sid] = SurfaceInfo(sid, kind, mats.get(ref, ""))
    if not surfaces:
        raise SceneError(f"scene file {str(p)!r} has no <shape>: nothing to reflect off")
    return MitsubaScene(p, surfaces)
