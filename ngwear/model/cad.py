"""The user's own parts: CAD files, mesh files and Netgen/NGSolve objects given in Python.

``geometry.kind = "step"``: a STEP file (also IGES or BREP) read by Netgen's OpenCASCADE; its named
faces are the boundaries, one of them ``contact``.  BREP carries no names: they are read from a
sidecar ``<file>.names.json`` (the face names in the shape's face order) when there is one.
``geometry.kind = "mesh"``: a Netgen ``.vol`` or Gmsh ``.msh`` mesh with named boundaries.  Every
solid (region) of the file is the body.  A ``netgen.occ`` shape or an (NGSolve or Netgen) mesh given
in Python is written once to a file in the cache, named by a hash of its content, so that a scene
stays plain data that TOML, JSON and the result folders can hold.  Shapes go to BREP + sidecar, not
STEP: STEP names a face's geometry, so faces that share it (the ends of an extrusion) lose a name.
"""
from __future__ import annotations

import hashlib
import json
import os
import tempfile
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import netgen.meshing
import ngsolve as ngs
import numpy as np
from netgen.occ import OCCGeometry, TopoDS_Shape

from .cache import cache_dir
from .kinds import Kind, register

SHAPE_FILES = (".step", ".stp", ".iges", ".igs", ".brep")
MESH_FILES = (".vol", ".msh")


class PartError(ValueError):
    """A part file cannot be read (the scene turns this into a message naming ``geometry.file``)."""


@dataclass(frozen=True)
class Part:
    """What validation needs to know of a part file: dimension, boundary names, bounding-box diagonal."""

    dim: int
    boundaries: tuple[str, ...]
    extent: float


def describe(path: str, kind: str) -> Part:
    """The dimension, named boundaries and size of a part file (cached by path, size and mtime)."""
    file = Path(path)
    if not file.is_file():
        raise PartError(f"{path} does not exist")
    suffixes = KINDS_OF_FILES[kind].files
    if file.suffix.lower() not in suffixes:
        raise PartError(f"{file.name} is not a {' / '.join(suffixes)} file")
    stat = file.stat()
    return _describe(str(file.resolve()), kind, stat.st_size, stat.st_mtime_ns)


@lru_cache(maxsize=32)
def _describe(path: str, kind: str, size: int, mtime: int) -> Part:
    if kind == "step":
        shape = read_shape(path)
        lo, hi = (np.array(corner) for corner in shape.bounding_box)
        names = {face.name for face in shape.faces if face.name}
        return Part(3, tuple(sorted(names)), float(np.linalg.norm(hi - lo)))
    mesh = read_mesh(path)
    points = np.array([p.p for p in mesh.Points()])
    names = set(ngs.Mesh(mesh).GetBoundaries())
    extent = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))) if len(points) else 0.0
    return Part(mesh.dim, tuple(sorted(n for n in names if n)), extent)


def read_shape(path: str) -> TopoDS_Shape:
    """The OCC shape of a STEP / IGES / BREP file (a BREP's face names from its sidecar)."""
    try:
        shape = OCCGeometry(str(path)).shape
    except Exception as err:  # Netgen raises its own exception type with the reader's message
        raise PartError(f"cannot read {Path(path).name} ({err})") from None
    sidecar = Path(f"{path}.names.json")
    if sidecar.is_file():
        names = json.loads(sidecar.read_text())
        if len(names) != len(shape.faces):
            raise PartError(f"{sidecar.name} names {len(names)} faces, the shape has {len(shape.faces)}")
        for face, name in zip(shape.faces, names):
            if name:
                face.name = name
    return shape


def read_mesh(path: str) -> netgen.meshing.Mesh:
    """The Netgen mesh of a ``.vol`` or Gmsh ``.msh`` file, every region renamed ``body``."""
    try:
        if Path(path).suffix.lower() == ".msh":
            from netgen.read_gmsh import ReadGmsh
            mesh = ReadGmsh(str(path))
        else:
            mesh = netgen.meshing.Mesh()
            mesh.Load(str(path))
    except Exception as err:  # as above
        raise PartError(f"cannot read {Path(path).name} ({err})") from None
    for index in range(1, mesh.GetNDomains() + 1):
        mesh.SetMaterial(index, "body")
    return mesh


def store(part) -> tuple[str, str]:
    """(kind, path) of a file in the cache holding a ``netgen.occ`` shape or a mesh given in Python."""
    folder = cache_dir() / "parts"
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder) as scratch:
        if isinstance(part, TopoDS_Shape):
            names = [face.name for face in part.faces]
            target, kind = folder / f"{_fingerprint(part, names)}.brep", "step"
            if not target.is_file():
                part.WriteBrep(str(Path(scratch) / "shape.brep"))
                Path(f"{target}.names.json").write_text(json.dumps(names))
                os.replace(Path(scratch) / "shape.brep", target)
        else:
            mesh = getattr(part, "ngmesh", part)
            if not isinstance(mesh, netgen.meshing.Mesh):
                raise PartError(f"geometry.shape must be a netgen.occ shape or a mesh (got {type(part).__name__})")
            written = Path(scratch) / "mesh.vol"
            mesh.Save(str(written))
            target, kind = folder / f"{hashlib.sha256(written.read_bytes()).hexdigest()[:16]}.vol", "mesh"
            if not target.is_file():
                os.replace(written, target)
    return kind, str(target)


def _fingerprint(shape: TopoDS_Shape, names: list) -> str:
    """A hash of what a shape is (vertices, faces' areas and centres, names), not of how it was last written."""
    faces = [(round(f.mass, 12), *(round(c, 12) for c in (f.center.x, f.center.y, f.center.z))) for f in shape.faces]
    vertices = sorted(tuple(round(c, 12) for c in (v.p.x, v.p.y, v.p.z)) for v in shape.vertices)
    return hashlib.sha256(json.dumps([faces, vertices, names]).encode()).hexdigest()[:16]


def _step(geometry, mesh):
    """The shape of the part file; every solid is the body."""
    body = read_shape(geometry.file)
    body.solids.name = "body"
    if mesh.contact_maxh is not None:
        for face in body.faces:
            if face.name == "contact":
                face.maxh = mesh.contact_maxh
    return body


KINDS_OF_FILES = {
    kind.name: register(kind) for kind in (
        Kind("step", "`step` a STEP/IGES/BREP file", None, build=_step, options=("geometry.file",), files=SHAPE_FILES),
        Kind("mesh", "`mesh` a Netgen .vol or Gmsh .msh file", None, options=("geometry.file",), files=MESH_FILES))}


def fingerprint(path: str) -> tuple:
    """What identifies a part file's content cheaply: its path, size and modification time (and its sidecar's)."""
    stats = [Path(p).stat() for p in (path, f"{path}.names.json") if Path(p).is_file()]
    return (str(Path(path).resolve()), *((s.st_size, s.st_mtime_ns) for s in stats))
