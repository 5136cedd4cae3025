"""Netgen/OCC geometries with named boundaries and the soft layer under Γ_C.

The body is the region ``body``; its contact face/edge is named ``contact``.  With
``mesh.layer = true`` the soft layer of thickness g (the region ``layer``, outer face
``foundation``) is meshed too: it is not part of the elastic solve but carries the layer's
compression and wear for results and pictures (flat Γ_C only: ``strip`` and ``box``).
``mesh.contact_maxh`` refines Γ_C (for ``half_disk`` the arc within ``mesh.contact_zone`` of its
lowest point) and ``mesh.grading`` (Netgen's, default 0.3) slows the growth of the elements away
from it.  Meshes are cached on disk by a hash of what determines them (``$NGWEAR_CACHE`` or
``~/.cache/ngwear``).

Shapes, all with Γ_C at and above x_d = 0 and touching it:

* ``strip`` [0,Lx]×[0,Ly]: boundaries left, right, top, contact (y = 0);
* ``box`` [0,Lx]×[0,Ly]×[0,Lz]: left, right, front, back, top, contact (z = 0);
* ``half_disk``: the lower half of the disk of radius R centred at (0, R) — a section of a
  half-cylinder (plane strain): ``top`` the flat edge y = R, ``contact`` the arc, which touches
  y = 0 at its lowest point (0, 0).  The arc is four OCC edges split at x = ±zone and at x = 0, so
  the lowest point is always a mesh vertex and the zone can be refined on its own.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

import netgen.meshing
import ngsolve as ngs
from netgen.occ import (
    ArcOfCircle,
    Box,
    Face,
    Glue,
    MoveTo,
    OCCGeometry,
    Pnt,
    Rectangle,
    Segment,
    Wire,
    X,
    Y,
    Z,
)

from .scene import Scene, SceneError

CACHE_VERSION = 1


def _strip(size, gap, layer, mesh):
    lx, ly = size
    body = Rectangle(lx, ly).Face()
    body.faces.name = "body"
    body.edges.Min(X).name = "left"
    body.edges.Max(X).name = "right"
    body.edges.Max(Y).name = "top"
    body.edges.Min(Y).name = "contact"
    if mesh.contact_maxh is not None:
        body.edges.Min(Y).maxh = mesh.contact_maxh
    if not layer:
        return body
    soft = MoveTo(0, -gap).Rectangle(lx, gap).Face()
    soft.faces.name = "layer"
    soft.edges.name = "layer_side"
    soft.edges.Min(Y).name = "foundation"
    soft.edges.Max(Y).name = "contact"
    if mesh.contact_maxh is not None:
        soft.edges.Max(Y).maxh = mesh.contact_maxh
    return Glue([body, soft])


def _half_disk(size, gap, layer, mesh):
    """Lower half of the disk |x − (0, R)| ≤ R: flat edge ``top`` at y = R, arc ``contact``."""
    radius = size[0]
    zone = mesh.contact_zone if mesh.contact_zone is not None else radius / 4
    quarter = math.pi / 2
    theta = min(math.asin(min(zone / radius, 1.0)), quarter)

    def at(phi):  # point of the arc at angle phi from the downward vertical, positive towards +x
        return Pnt(radius * math.sin(phi), radius * (1 - math.cos(phi)), 0)

    def arc(a, b):
        return ArcOfCircle(at(a), at((a + b) / 2), at(b))

    zone_arcs = [arc(-theta, 0.0), arc(0.0, theta)]
    full = theta >= quarter * (1 - 1e-9)
    arcs = zone_arcs if full else [arc(-quarter, -theta), *zone_arcs, arc(theta, quarter)]
    top = Segment(at(quarter), at(-quarter))
    body = Face(Wire([*arcs, top]))
    body.faces.name = "body"
    body.edges.name = "contact"
    body.edges.Max(Y).name = "top"
    if mesh.contact_maxh is not None:
        for edge in body.edges:
            if edge.name == "contact" and abs(edge.center.x) < zone:
                edge.maxh = mesh.contact_maxh
    return body


def _box(size, gap, layer, mesh):
    lx, ly, lz = size
    body = Box(Pnt(0, 0, 0), Pnt(lx, ly, lz))
    body.solids.name = "body"
    for name, face in (("left", body.faces.Min(X)), ("right", body.faces.Max(X)),
                       ("front", body.faces.Min(Y)), ("back", body.faces.Max(Y)),
                       ("top", body.faces.Max(Z)), ("contact", body.faces.Min(Z))):
        face.name = name
    if mesh.contact_maxh is not None:
        body.faces.Min(Z).maxh = mesh.contact_maxh
    if not layer:
        return body
    soft = Box(Pnt(0, 0, -gap), Pnt(lx, ly, 0))
    soft.solids.name = "layer"
    soft.faces.name = "layer_side"
    soft.faces.Min(Z).name = "foundation"
    soft.faces.Max(Z).name = "contact"
    if mesh.contact_maxh is not None:
        soft.faces.Max(Z).maxh = mesh.contact_maxh
    return Glue([body, soft])


SHAPES = {"strip": _strip, "box": _box, "half_disk": _half_disk}


def mesh_key(scene: Scene) -> str:
    """Hash of everything the mesh depends on (not loads, material, time or contact laws)."""
    g, m = scene.geometry, scene.mesh
    spec = {"v": CACHE_VERSION, "kind": g.kind, "size": g.size, "maxh": m.maxh, "layer": m.layer,
            "gap": scene.contact.gap if m.layer else None}
    optional = {"contact_maxh": m.contact_maxh, "contact_zone": m.contact_zone, "grading": m.grading}
    spec.update({k: v for k, v in optional.items() if v is not None})  # unset: keys stay as they were
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:16]


def cache_dir() -> Path:
    return Path(os.environ.get("NGWEAR_CACHE", Path.home() / ".cache" / "ngwear"))


def _check_complete(mesh: ngs.Mesh, measure: float) -> None:
    """Netgen can leave faces unmeshed with only a printed warning: compare the meshed measure."""
    meshed = ngs.Integrate(ngs.CF(1.0), mesh)
    if abs(meshed - measure) > 0.01 * measure:
        raise SceneError(f"mesh: Netgen meshed only {meshed / measure:.1%} of the geometry; "
                         "raise mesh.grading or mesh.contact_maxh, or change mesh.maxh")


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
    shape = SHAPES[g.kind](g.size, gap, m.layer, m)
    options = {"grading": m.grading} if m.grading is not None else {}
    ngmesh = OCCGeometry(shape, dim=g.dim).GenerateMesh(maxh=m.maxh, **options)
    parts = shape.faces if g.dim == 2 else shape.solids
    _check_complete(ngs.Mesh(ngmesh), sum(part.mass for part in parts))
    if use_cache:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.vol")
        ngmesh.Save(str(tmp))
        tmp.replace(path)
    return ngs.Mesh(ngmesh)
