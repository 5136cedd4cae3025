"""Reading part files (STEP / IGES / BREP shapes, Netgen .vol and Gmsh .msh meshes), safely.

Files from outside are read first in a child process (:func:`describe`, cached by path, size and mtime):
Netgen and OpenCASCADE trust their input, and a damaged file (a ``.vol`` cut short) can crash them, which
in the child is a :class:`PartError` naming the file instead of the end of the run, the explorer or a
study's client.  :func:`read_mesh` and :func:`read_shape` read a file in this process only once it has
been described.  The child (:func:`ngwear.child.run`) imports this module, not ngwear's API.

Regions: the solid (a mesh's material) that carries the faces named ``contact`` is the region ``body``, and
so is an unnamed one (no name, or Netgen's ``default``); every other solid (material) is the region of its
name (:func:`solid_regions`, :func:`mesh_regions`).
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import netgen.meshing
import numpy as np
from netgen.occ import OCCGeometry, TopoDS_Shape

from ..child import ChildError, run

SHAPE_FILES = (".step", ".stp", ".iges", ".igs", ".brep")
MESH_FILES = (".vol", ".msh")
SUFFIXES = {"step": SHAPE_FILES, "mesh": MESH_FILES}


class PartError(ValueError):
    """A part file cannot be read (the scene turns this into a message naming ``geometry.file``)."""


@dataclass(frozen=True)
class Part:
    """What validation needs to know of a part file: dimension, boundary names, bounding-box diagonal, regions."""

    dim: int
    boundaries: tuple[str, ...]
    extent: float
    regions: tuple[str, ...]


def describe(path: str, kind: str) -> Part:
    """The dimension, named boundaries and size of a part file, or a PartError saying why it cannot be read.

    The file is read in a child process (see the module docstring); the answer is cached by path, size and mtime.
    """
    file = Path(path)
    if not file.is_file():
        raise PartError(f"{path} does not exist")
    suffixes = SUFFIXES[kind]
    if file.suffix.lower() not in suffixes:
        raise PartError(f"{file.name} is not a {' / '.join(suffixes)} file")
    stat = file.stat()
    return _describe(str(file.resolve()), kind, stat.st_size, stat.st_mtime_ns)


@lru_cache(maxsize=32)
def _describe(path: str, kind: str, size: int, mtime: int) -> Part:
    """:func:`_read` in a child process, whose crash is a PartError."""
    try:
        return run(_read, path, kind, quiet=True)
    except ChildError as err:
        if isinstance(err.__cause__, PartError):
            raise err.__cause__ from None
        name = Path(path).name
        if err.signal:
            reader = "OpenCASCADE" if kind == "step" else "Netgen"
            raise PartError(f"{reader} crashed reading {name} ({err.signal}): the file is damaged or cut short") from None
        raise PartError(f"cannot read {name} ({err})") from None


def _read(path: str, kind: str) -> Part:
    """Dimension, boundary names and extent of a part file, read in this process."""
    if kind == "step":
        shape = _load_shape(path)
        if not shape.faces:
            raise PartError(f"{Path(path).name} holds no shape (no faces): empty, or not a STEP / IGES / BREP file")
        lo, hi = (np.array(corner) for corner in shape.bounding_box)
        names = {face.name for face in shape.faces if face.name}
        return Part(3, tuple(sorted(names)), float(np.linalg.norm(hi - lo)), _listed(solid_regions(shape)))
    mesh = _load_mesh(path)
    points = np.array([p.p for p in mesh.Points()])
    if not len(points):
        raise PartError(f"{Path(path).name} holds no mesh (no points): empty, or not a Netgen .vol / Gmsh .msh file")
    names = set(mesh.GetRegionNames(codim=1))
    extent = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    return Part(mesh.dim, tuple(sorted(n for n in names if n)), extent, _listed(domains(mesh)))   # mesh_regions' names


UNNAMED = (None, "", "default")
"""Names of unnamed solids and materials (Netgen's ``default``): they are the body."""


def solid_regions(shape: TopoDS_Shape) -> list[str]:
    """The region of each of the shape's solids: ``body`` where it carries a face ``contact`` or has no name."""
    return ["body" if solid.name in UNNAMED or any(face.name == "contact" for face in solid.faces) else solid.name
            for solid in shape.solids]


def mesh_regions(mesh: netgen.meshing.Mesh) -> list[str]:
    """The region of each of the mesh's materials (domains 1, 2, …).

    ``body`` where the material has no name or its elements have a facet on the boundary ``contact``, else its
    name.  The facets come from NGSolve's topology (Netgen's Python API lacks the domains of 2D boundary segments).
    """
    import ngsolve

    topology = ngsolve.Mesh(mesh)
    facets = (lambda el: el.faces) if mesh.dim == 3 else (lambda el: el.edges)
    contact = {f.nr for el in topology.Elements(ngsolve.BND) if el.mat == "contact" for f in facets(el)}
    touching = {el.index for el in topology.Elements(ngsolve.VOL) if contact.intersection(f.nr for f in facets(el))}
    return ["body" if name in UNNAMED or index in touching else name for index, name in enumerate(domains(mesh))]


def domains(mesh: netgen.meshing.Mesh) -> list[str]:
    """The names of the mesh's materials, domains 1, 2, … (in 2D Netgen's codim-0 names hold its edges' too)."""
    return [mesh.GetMaterial(index) for index in range(1, mesh.GetNDomains() + 1)]


def _listed(regions) -> tuple[str, ...]:
    """The distinct regions, ``body`` first."""
    return tuple(dict.fromkeys(["body", *regions]))


def read_shape(path: str) -> TopoDS_Shape:
    """The OCC shape of a STEP / IGES / BREP file (a BREP's face names from its sidecar), once described."""
    describe(path, "step")
    return _load_shape(path)


def read_mesh(path: str) -> netgen.meshing.Mesh:
    """The Netgen mesh of a ``.vol`` or Gmsh ``.msh`` file, its materials named as regions, once described."""
    describe(path, "mesh")
    return _load_mesh(path)


def _load_shape(path: str) -> TopoDS_Shape:
    try:
        shape = OCCGeometry(str(path)).shape
    except Exception as err:  # Netgen raises its own exception type with the reader's message
        raise PartError(f"cannot read {Path(path).name} ({err})") from None
    sidecar = Path(f"{path}.names.json")
    if sidecar.is_file():
        names = json.loads(sidecar.read_text())
        names = names if isinstance(names, dict) else {"faces": names}     # before solids were named: faces only
        for what, shapes in (("faces", shape.faces), ("solids", shape.solids)):
            listed = names.get(what, [None] * len(shapes))
            if len(listed) != len(shapes):
                raise PartError(f"{sidecar.name} names {len(listed)} {what}, the shape has {len(shapes)}")
            for part, name in zip(shapes, listed):
                if name:
                    part.name = name
    return shape


def _load_mesh(path: str) -> netgen.meshing.Mesh:
    try:
        if Path(path).suffix.lower() == ".msh":
            from netgen.read_gmsh import ReadGmsh
            mesh = ReadGmsh(str(path))
        else:
            mesh = netgen.meshing.Mesh()
            mesh.Load(str(path))
    except Exception as err:  # as above
        raise PartError(f"cannot read {Path(path).name} ({err})") from None
    if mesh.GetNDomains() and len(mesh.Points()):
        for index, name in enumerate(mesh_regions(mesh), start=1):
            mesh.SetMaterial(index, name)
    return mesh
