"""Netgen/OCC geometries with named boundaries and the soft layer under Γ_C.

The body is the region ``body``; its contact face/edge is named ``contact``.  With
``mesh.layer = true`` the soft layer of thickness g (the region ``layer``, outer face
``foundation``) is meshed too: it is not part of the elastic solve but carries the layer's
compression and wear for results and pictures.  Meshes are cached on disk by a hash of what
determines them (``$NGWEAR_CACHE`` or ``~/.cache/ngwear``).
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import netgen.meshing
import ngsolve as ngs
from netgen.occ import X, Y, Z, Box, Glue, MoveTo, OCCGeometry, Pnt, Rectangle

from .scene import Scene, SceneError

CACHE_VERSION = 1


def _strip(size, gap, layer):
    lx, ly = size
    body = Rectangle(lx, ly).Face()
    body.faces.name = "body"
    body.edges.Min(X).name = "left"
    body.edges.Max(X).name = "right"
    body.edges.Max(Y).name = "top"
    body.edges.Min(Y).name = "contact"
    if not layer:
        return body
    soft = MoveTo(0, -gap).Rectangle(lx, gap).Face()
    soft.faces.name = "layer"
    soft.edges.name = "layer_side"
    soft.edges.Min(Y).name = "foundation"
    soft.edges.Max(Y).name = "contact"
    return Glue([body, soft])


def _box(size, gap, layer):
    lx, ly, lz = size
    body = Box(Pnt(0, 0, 0), Pnt(lx, ly, lz))
    body.solids.name = "body"
    for name, face in (("left", body.faces.Min(X)), ("right", body.faces.Max(X)),
                       ("front", body.faces.Min(Y)), ("back", body.faces.Max(Y)),
                       ("top", body.faces.Max(Z)), ("contact", body.faces.Min(Z))):
        face.name = name
    if not layer:
        return body
    soft = Box(Pnt(0, 0, -gap), Pnt(lx, ly, 0))
    soft.solids.name = "layer"
    soft.faces.name = "layer_side"
    soft.faces.Min(Z).name = "foundation"
    soft.faces.Max(Z).name = "contact"
    return Glue([body, soft])


SHAPES = {"strip": _strip, "box": _box}


def mesh_key(scene: Scene) -> str:
    """Hash of everything the mesh depends on (not loads, material, time or contact laws)."""
    g, m = scene.geometry, scene.mesh
    spec = {"v": CACHE_VERSION, "kind": g.kind, "size": g.size, "maxh": m.maxh, "layer": m.layer,
            "gap": scene.contact.gap if m.layer else None}
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:16]


def cache_dir() -> Path:
    return Path(os.environ.get("NGWEAR_CACHE", Path.home() / ".cache" / "ngwear"))


def build_mesh(scene: Scene, use_cache: bool = True) -> ngs.Mesh:
    """Mesh the scene's body (and soft layer), reusing the on-disk cache when possible."""
    g, m = scene.geometry, scene.mesh
    gap = scene.contact.gap
    if m.layer and gap < m.maxh / 50:
        raise SceneError(f"mesh.layer: the layer (contact.gap = {gap}) is too thin to mesh at "
                         f"mesh.maxh = {m.maxh}; set mesh.layer = false or gap >= maxh/50")
    path = cache_dir() / "meshes" / f"{mesh_key(scene)}.vol"
    if use_cache and path.is_file():
        ngmesh = netgen.meshing.Mesh(dim=g.dim)
        ngmesh.Load(str(path))
        return ngs.Mesh(ngmesh)
    shape = SHAPES[g.kind](g.size, gap, m.layer)
    ngmesh = OCCGeometry(shape, dim=g.dim).GenerateMesh(maxh=m.maxh)
    if use_cache:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.vol")
        ngmesh.Save(str(tmp))
        tmp.replace(path)
    return ngs.Mesh(ngmesh)
