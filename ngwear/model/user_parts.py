"""The user's own parts: CAD files, mesh files and Netgen/NGSolve objects given in Python.

``geometry.kind = "step"``: a STEP file (also IGES or BREP) read by Netgen's OpenCASCADE; its named
faces are the boundaries, one of them ``contact``, and its named solids the regions: the solid that
carries ``contact`` (and any unnamed one) is ``body``, the others keep their names.  Solids that touch
are glued (``Glue``), so the mesh is conforming across the faces they share.  BREP carries no names:
they are read from a sidecar ``<file>.names.json`` (``{"faces": [...], "solids": [...]}`` in the
shape's order; a plain list names the faces) when there is one.  ``geometry.kind = "mesh"``: a Netgen
``.vol`` or Gmsh ``.msh`` mesh with named boundaries; its materials are the regions, by the same rule.
A ``netgen.occ`` shape or an (NGSolve or Netgen) mesh given in Python is written once to a file in the
cache, named by a hash of its content, so that a scene stays plain data that TOML, JSON and the result
folders can hold.  Shapes go to BREP + sidecar, not STEP: STEP names a face's geometry, so faces that
share it (the ends of an extrusion) lose a name.

Files are read by :mod:`ngwear.model.part_files` (in a child process first).
"""
from __future__ import annotations

import hashlib
import json
import os
import tempfile
from pathlib import Path

import netgen.meshing
from netgen.occ import Glue, TopoDS_Shape

from .kinds import Kind, register
from .part_files import MESH_FILES, SHAPE_FILES, Part, PartError, describe, read_mesh, read_shape, solid_regions

__all__ = ["Part", "PartError", "cache_dir", "content_hash", "describe", "fingerprint", "read_mesh", "read_shape", "store"]


def cache_dir() -> Path:
    """``$NGWEAR_CACHE``, or ``~/.cache/ngwear``: where meshes and the parts given in Python are kept."""
    return Path(os.environ.get("NGWEAR_CACHE", Path.home() / ".cache" / "ngwear"))


def store(part) -> tuple[str, str]:
    """(kind, path) of a file in the cache holding a ``netgen.occ`` shape or a mesh given in Python."""
    folder = cache_dir() / "parts"
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder) as scratch:
        if isinstance(part, TopoDS_Shape):
            names = {"faces": [face.name for face in part.faces], "solids": [solid.name for solid in part.solids]}
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


def _fingerprint(shape: TopoDS_Shape, names: dict) -> str:
    """A hash of what a shape is (vertices, faces' areas and centres, names), not of how it was last written."""
    faces = [(round(f.mass, 12), *(round(c, 12) for c in (f.center.x, f.center.y, f.center.z))) for f in shape.faces]
    vertices = sorted(tuple(round(c, 12) for c in (v.p.x, v.p.y, v.p.z)) for v in shape.vertices)
    return hashlib.sha256(json.dumps([faces, vertices, names]).encode()).hexdigest()[:16]


def _step(geometry, mesh):
    """The shape of the part file, its solids glued and named as regions (:func:`solid_regions`)."""
    part = read_shape(geometry.file)
    if len(part.solids) > 1:
        part = Glue(list(part.solids))
    for solid, region in zip(part.solids, solid_regions(part)):
        solid.name = region
    if mesh.contact_maxh is not None:
        for face in part.faces:
            if face.name == "contact":
                face.maxh = mesh.contact_maxh
    return part


KINDS_OF_FILES = {
    kind.name: register(kind) for kind in (
        Kind("step", "`step` a STEP/IGES/BREP file", None, build=_step, options=("geometry.file",), files=SHAPE_FILES),
        Kind("mesh", "`mesh` a Netgen .vol or Gmsh .msh file", None, options=("geometry.file",), files=MESH_FILES))}


def fingerprint(path: str) -> tuple:
    """What identifies a part file's content cheaply: its path, size and modification time (and its sidecar's)."""
    stats = [Path(p).stat() for p in (path, f"{path}.names.json") if Path(p).is_file()]
    return (str(Path(path).resolve()), *((s.st_size, s.st_mtime_ns) for s in stats))


def content_hash(path: str) -> str:
    """SHA-256 of a part file's bytes and its sidecar's: the same wherever the file lies and however it was copied."""
    sidecar = Path(f"{path}.names.json")
    names = sidecar.read_bytes() if sidecar.is_file() else b""
    return hashlib.sha256(Path(path).read_bytes() + names).hexdigest()
