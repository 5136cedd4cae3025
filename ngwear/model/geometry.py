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
  the lowest point is always a mesh vertex and the zone can be refined on its own;
* ``pad``: the annular sector r_i ≤ r ≤ r_o, |φ| ≤ angle/2, 0 ≤ z ≤ thickness of a disc brake pad on
  a disc turning about the z axis: contact (z = 0), back (z = thickness), inner, outer, leading
  (φ = −angle/2, where a point of a disc turning with ω_z > 0 enters) and trailing;
* ``pin``: a cylinder of radius a about the vertical line through ``position``, from z = 0 to
  z = length: contact (the flat end, or a spherical cap of radius R touching z = 0), back, side;
* ``step``: the shape of a STEP / IGES / BREP file, its named faces the boundaries; ``mesh``: a
  mesh file as it is (see :mod:`ngwear.model.cad`).
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
    Axis,
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

from .cad import read_mesh, read_shape
from .scene import Scene, SceneError

CACHE_VERSION = 2


def _strip(geometry, mesh):
    lx, ly = geometry.size
    body = Rectangle(lx, ly).Face()
    body.faces.name = "body"
    body.edges.Min(X).name = "left"
    body.edges.Max(X).name = "right"
    body.edges.Max(Y).name = "top"
    body.edges.Min(Y).name = "contact"
    if mesh.contact_maxh is not None:
        body.edges.Min(Y).maxh = mesh.contact_maxh
    return body


def _half_disk(geometry, mesh):
    """Lower half of the disk |x − (0, R)| ≤ R: flat edge ``top`` at y = R, arc ``contact``."""
    radius = geometry.size[0]
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


def _box(geometry, mesh):
    lx, ly, lz = geometry.size
    body = Box(Pnt(0, 0, 0), Pnt(lx, ly, lz))
    body.solids.name = "body"
    for name, face in (("left", body.faces.Min(X)), ("right", body.faces.Max(X)),
                       ("front", body.faces.Min(Y)), ("back", body.faces.Max(Y)),
                       ("top", body.faces.Max(Z)), ("contact", body.faces.Min(Z))):
        face.name = name
    if mesh.contact_maxh is not None:
        body.faces.Min(Z).maxh = mesh.contact_maxh
    return body


def _pad(geometry, mesh):
    """The annular sector r_i ≤ r ≤ r_o, |φ| ≤ angle/2 in the plane z = 0, extruded to z = thickness."""
    inner, outer, angle, thickness = geometry.size
    half = math.radians(angle) / 2

    def at(r, phi):
        return Pnt(r * math.cos(phi), r * math.sin(phi), 0)

    sector = Wire([Segment(at(inner, -half), at(outer, -half)), ArcOfCircle(at(outer, -half), at(outer, 0), at(outer, half)),
                   Segment(at(outer, half), at(inner, half)), ArcOfCircle(at(inner, half), at(inner, 0), at(inner, -half))])
    body = Face(sector).Extrude(thickness)
    body.solids.name = "body"
    body.faces.Min(Z).name, body.faces.Max(Z).name = "contact", "back"
    sides = [f for f in body.faces if f.name not in ("contact", "back")]
    ends = sorted((f for f in sides if abs(f.center.y) > 1e-9 * outer), key=lambda f: f.center.y)
    arcs = sorted((f for f in sides if abs(f.center.y) <= 1e-9 * outer), key=lambda f: f.mass)
    for face, name in zip([*ends, *arcs], ("leading", "trailing", "inner", "outer")):
        face.name = name
    if mesh.contact_maxh is not None:
        body.faces.Min(Z).maxh = mesh.contact_maxh
    return body


def _pin(geometry, mesh):
    """A cylinder of radius a on the disc at ``position``, flat or with a spherical cap of radius R below.

    Its profile in a half-plane through the axis, revolved about the axis (robust, unlike booleans of
    a sphere and a cylinder): the axis, the back, the side down to the cap's rim, the end to the tip.
    """
    radius, length = geometry.size
    x, y = geometry.position

    def at(r, z):
        return Pnt(x + r, y, z)

    if geometry.end == "sphere":
        cap_radius = geometry.end_radius
        cap = cap_radius - math.sqrt(cap_radius ** 2 - radius ** 2)
        half = 0.5 * math.asin(radius / cap_radius)
        end = ArcOfCircle(at(radius, cap), at(cap_radius * math.sin(half), cap_radius * (1 - math.cos(half))),
                          at(0, 0))
    else:
        cap, end = 0.0, Segment(at(radius, 0), at(0, 0))
    profile = Wire([Segment(at(0, 0), at(0, length)), Segment(at(0, length), at(radius, length)),
                    Segment(at(radius, length), at(radius, cap)), end])
    body = Face(profile).Revolve(Axis(Pnt(x, y, 0), Z), 360)
    body.solids.name = "body"
    body.faces.name = "side"
    body.faces.Min(Z).name, body.faces.Max(Z).name = "contact", "back"
    if mesh.contact_maxh is not None:
        body.faces.Min(Z).maxh = mesh.contact_maxh
    return body


def _step(geometry, mesh):
    """The shape of the part file; every solid is the body."""
    body = read_shape(geometry.file)
    body.solids.name = "body"
    if mesh.contact_maxh is not None:
        for face in body.faces:
            if face.name == "contact":
                face.maxh = mesh.contact_maxh
    return body


SHAPES = {"strip": _strip, "box": _box, "half_disk": _half_disk, "pad": _pad, "pin": _pin, "step": _step}


def mesh_key(scene: Scene) -> str:
    """Hash of everything the mesh depends on (not loads, material, contact laws or time)."""
    g, m = scene.geometry, scene.mesh
    spec = {"v": CACHE_VERSION, "kind": g.kind, "size": g.size, "maxh": m.maxh}
    if g.file is not None:
        sidecar = Path(f"{g.file}.names.json")
        names = sidecar.read_bytes() if sidecar.is_file() else b""
        spec["file"] = hashlib.sha256(Path(g.file).read_bytes() + names).hexdigest()
    optional = {"contact_maxh": m.contact_maxh, "contact_zone": m.contact_zone, "grading": m.grading,
                "position": g.position, "end": g.end, "end_radius": g.end_radius}
    spec.update({k: v for k, v in optional.items() if v is not None})  # unset: keys stay as they were
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:16]


def cache_dir() -> Path:
    return Path(os.environ.get("NGWEAR_CACHE", Path.home() / ".cache" / "ngwear"))


def _check_complete(mesh: ngs.Mesh, measure: float) -> None:
    """Netgen can leave faces unmeshed with only a printed warning: compare the meshed measure.

    Straight-sided elements under curved faces lose a few per cent of the measure at a coarse maxh
    (a cylinder of radius 2 maxh: 3 %); a partial meshing loses whole regions.
    """
    meshed = ngs.Integrate(ngs.CF(1.0), mesh)
    if abs(meshed - measure) > 0.1 * measure:
        raise SceneError(f"mesh: Netgen meshed only {meshed / measure:.1%} of the geometry; "
                         "raise mesh.grading or mesh.contact_maxh, or change mesh.maxh")


def build_mesh(scene: Scene, use_cache: bool = True) -> ngs.Mesh:
    """Mesh the scene's body, reusing the on-disk cache when possible (a mesh file is read as it is).

    A new mesh is returned as read back from its file: the file stores the vertices to the last bit
    that reading restores, so a first run, a cached run and a run resumed from its output folder's
    ``mesh.vol`` compute on the same numbers.
    """
    g, m = scene.geometry, scene.mesh
    if g.kind == "mesh":
        return ngs.Mesh(read_mesh(g.file))
    path = cache_dir() / "meshes" / f"{mesh_key(scene)}.vol"
    if not (use_cache and path.is_file()):
        shape = SHAPES[g.kind](g, m)
        options = {"grading": m.grading} if m.grading is not None else {}
        ngmesh = OCCGeometry(shape, dim=g.dim).GenerateMesh(maxh=m.maxh, **options)
        parts = shape.faces if g.dim == 2 else shape.solids
        _check_complete(ngs.Mesh(ngmesh), sum(part.mass for part in parts))
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp.vol")
        ngmesh.Save(str(tmp))
        if not use_cache:
            mesh = load_mesh(tmp, g.dim)
            tmp.unlink()
            return mesh
        tmp.replace(path)
    return load_mesh(path, g.dim)


def load_mesh(path, dim: int) -> ngs.Mesh:
    """A Netgen ``.vol`` mesh file as an NGSolve mesh."""
    ngmesh = netgen.meshing.Mesh(dim=dim)
    ngmesh.Load(str(path))
    return ngs.Mesh(ngmesh)
