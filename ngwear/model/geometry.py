"""Netgen/OCC geometries with named boundaries.

The body is the region ``body``; its contact face/edge is named ``contact``.  The soft layer is
not meshed: it lives on the contact points (its compression and wear are nodal) and pictures draw
it by offsetting Γ_C along ν.  ``mesh.contact_maxh`` refines Γ_C (for ``half_disk`` the arc
within ``mesh.contact_zone`` of its lowest point) and ``mesh.grading`` (Netgen's, default 0.3)
slows the growth of the elements away from it.  Meshes are cached on disk by a hash of what
determines them (``$NGWEAR_CACHE`` or ``~/.cache/ngwear``).

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

CACHE_VERSION = 2


def _strip(size, mesh):
    lx, ly = size
    body = Rectangle(lx, ly).Face()
    body.faces.name = "body"
    body.edges.Min(X).name = "left"
    body.edges.Max(X).name = "right"
    body.edges.Max(Y).name = "top"
    body.edges.Min(Y).name = "contact"
    if mesh.contact_maxh is not None:
        body.edges.Min(Y).maxh = mesh.contact_maxh
    return body


def _half_disk(size, mesh):
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


def _box(size, mesh):
    lx, ly, lz = size
    body = Box(Pnt(0, 0, 0), Pnt(lx, ly, lz))
    body.solids.name = "body"
    for name, face in (("left", body.faces.Min(X)), ("right", body.faces.Max(X)),
                       ("front", body.faces.Min(Y)), ("back", body.faces.Max(Y)),
                       ("top", body.faces.Max(Z)), ("contact", body.faces.Min(Z))):
        face.name = name
    if mesh.contact_maxh is not None:
        body.faces.Min(Z).maxh = mesh.contact_maxh
    return body


SHAPES = {"strip": _strip, "box": _box, "half_disk": _half_disk}


def mesh_key(scene: Scene) -> str:
    """Hash of everything the mesh depends on (not loads, material, contact laws or time)."""
    g, m = scene.geometry, scene.mesh
    spec = {"v": CACHE_VERSION, "kind": g.kind, "size": g.size, "maxh": m.maxh}
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
    """Mesh the scene's body, reusing the on-disk cache when possible."""
    g, m = scene.geometry, scene.mesh
    path = cache_dir() / "meshes" / f"{mesh_key(scene)}.vol"
    if use_cache and path.is_file():
        ngmesh = netgen.meshing.Mesh(dim=g.dim)
        ngmesh.Load(str(path))
        return ngs.Mesh(ngmesh)
    shape = SHAPES[g.kind](g.size, m)
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
