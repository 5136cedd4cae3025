"""The built-in part kinds: their sizes, rules and OpenCASCADE shapes with named boundaries.

The body is the region ``body``; its contact face/edge is named ``contact``.  All shapes have Γ_C at and
above x_d = 0, touching it:

* ``strip`` [0,Lx]×[0,Ly]: boundaries left, right, top, contact (y = 0);
* ``box`` [0,Lx]×[0,Ly]×[0,Lz]: left, right, front, back, top, contact (z = 0);
* ``half_disk``: the lower half of the disk of radius R centred at (0, R), a section of a half-cylinder
  (plane strain): ``top`` the flat edge y = R, ``contact`` the arc, which touches y = 0 at its lowest
  point.  The arc is two OCC edges split at x = 0, so the lowest point is always a mesh vertex; with
  ``mesh.contact_maxh`` the arc is refined within ``mesh.contact_zone`` (default R/4) of it;
* ``pad``: the annular sector r_i ≤ r ≤ r_o, |φ| ≤ angle/2, 0 ≤ z ≤ thickness of a disc brake pad on a
  disc turning about the z axis: contact (z = 0), back (z = thickness), inner, outer, leading
  (φ = −angle/2, where a point of a disc turning with ω_z > 0 enters) and trailing;
* ``pin``: a cylinder of radius a about the vertical line through ``geometry.position``, from z = 0 to
  z = length: contact (the flat end, or a spherical cap of radius R touching z = 0), back, side.

``geometry.backing = t_b`` (strip, box, pad, pin) glues a second region ``backing`` of thickness t_b onto
the face opposite Γ_C, meshed conformingly with the body: the face between them is ``interface``, the
backing's outer face takes the name of the face it covers (``top`` of a strip or box, ``back`` of a pad or
pin) and its sides the names of the body's sides.  Every feature of a part (a side, the pad's inner arc,
the pin's cap, the backing) must be at least :data:`~ngwear.model.kinds.FEATURE` of its largest dimension:
thinner ones cannot be built or meshed.  ``mesh.contact_maxh`` sets the element size on Γ_C, or within
``mesh.contact_zone`` of ``mesh.zone_center`` only (:mod:`ngwear.model.zone`, for every kind).
"""
from __future__ import annotations

import math

from netgen.occ import ArcOfCircle, Axis, Box, Face, Glue, MoveTo, Pnt, Segment, Wire, X, Y, Z

from .keys import SceneError
from .kinds import FEATURE, Kind, check_features, register


def _refine_contact(face, mesh) -> None:
    if mesh.contact_maxh is not None:
        face.maxh = mesh.contact_maxh


# ---------------------------------------------------------------- strip and box


def _check_sides(g) -> None:
    check_features("geometry.size", g.size, {"shortest side": min(g.size)}, max(g.size))


def _stacked(make, geometry, mesh, height: float):
    """The body from 0 to ``height`` above Γ_C; with ``geometry.backing`` t_b, the backing glued on from there.

    ``make(low, high, bottom, top, region)`` builds one region between the heights, its faces (2D: edges)
    there named ``bottom`` and ``top``; the top face of the whole part is ``None`` (the kind's own name).
    """
    backing = geometry.backing
    body = make(0.0, height, "contact", "interface" if backing else None, "body")
    if not backing:
        return body
    return Glue([body, make(height, height + backing, "interface", None, "backing")])


def _strip(geometry, mesh):
    lx, ly = geometry.size

    def make(low, high, bottom, top, region):
        part = MoveTo(0, low).Rectangle(lx, high - low).Face()
        part.faces.name = region
        part.edges.Min(X).name, part.edges.Max(X).name = "left", "right"
        part.edges.Max(Y).name, part.edges.Min(Y).name = top or "top", bottom
        if bottom == "contact":
            _refine_contact(part.edges.Min(Y), mesh)
        return part

    return _stacked(make, geometry, mesh, ly)


def _box(geometry, mesh):
    lx, ly, lz = geometry.size

    def make(low, high, bottom, top, region):
        part = Box(Pnt(0, 0, low), Pnt(lx, ly, high))
        part.solids.name = region
        for name, face in (("left", part.faces.Min(X)), ("right", part.faces.Max(X)), ("front", part.faces.Min(Y)),
                           ("back", part.faces.Max(Y)), (top or "top", part.faces.Max(Z)), (bottom, part.faces.Min(Z))):
            face.name = name
        if bottom == "contact":
            _refine_contact(part.faces.Min(Z), mesh)
        return part

    return _stacked(make, geometry, mesh, lz)


register(Kind("strip", "`strip` [0,Lx]×[0,Ly] (2D)", 2, (3.0, 1.0), "`strip` [Lx, Ly]",
              ("left", "right", "top", "contact"), ("left",), check=_check_sides, build=_strip,
              options=("geometry.backing",), thickness=1))
register(Kind("box", "`box` [0,Lx]×[0,Ly]×[0,Lz]", 3, (1.0, 0.5, 0.5), "`box` [Lx, Ly, Lz]",
              ("left", "right", "front", "back", "top", "contact"), ("left",), check=_check_sides, build=_box,
              options=("geometry.backing",), thickness=2))


# ---------------------------------------------------------------- half disk


def _half_disk(geometry, mesh):
    """Lower half of the disk |x − (0, R)| ≤ R: flat edge ``top`` at y = R, arc ``contact`` split at its lowest point."""
    radius = geometry.size[0]

    def at(phi):  # point of the arc at angle phi from the downward vertical, positive towards +x
        return Pnt(radius * math.sin(phi), radius * (1 - math.cos(phi)), 0)

    quarter = math.pi / 2
    arcs = [ArcOfCircle(at(a), at((a + b) / 2), at(b)) for a, b in ((-quarter, 0.0), (0.0, quarter))]
    body = Face(Wire([*arcs, Segment(at(quarter), at(-quarter))]))
    body.faces.name = "body"
    body.edges.name = "contact"
    body.edges.Max(Y).name = "top"
    for edge in body.edges:
        if edge.name == "contact":
            _refine_contact(edge, mesh)
    return body


register(Kind("half_disk", "`half_disk` the lower half of the disk of radius R centred at (0, R) (2D)", 2, (1.0,),
              "`half_disk` [R]", ("top", "contact"), ("top",), build=_half_disk, zone=lambda size: size[0] / 4))


# ---------------------------------------------------------------- brake pad


def _pad_extent(size) -> float:
    return max(size[1], size[3])


def _check_pad(g) -> None:
    inner, outer, angle, thickness = g.size
    if not (inner < outer and angle < 360):
        raise SceneError("geometry.size: must be [r_inner, r_outer, angle_deg, thickness] with r_inner < r_outer "
                         f"and angle_deg < 360 (got {list(g.size)})")
    check_features("geometry.size", g.size, {"radial width": outer - inner, "thickness": thickness,
                                        "inner arc": inner * math.radians(angle)}, _pad_extent(g.size))


def _pad(geometry, mesh):
    """The annular sector r_i ≤ r ≤ r_o, |φ| ≤ angle/2 in the plane z = 0, extruded to z = thickness."""
    inner, outer, angle, thickness = geometry.size
    half = math.radians(angle) / 2

    def make(low, high, bottom, top, region):
        def at(r, phi):
            return Pnt(r * math.cos(phi), r * math.sin(phi), low)

        sector = Wire([Segment(at(inner, -half), at(outer, -half)),
                       ArcOfCircle(at(outer, -half), at(outer, 0), at(outer, half)),
                       Segment(at(outer, half), at(inner, half)),
                       ArcOfCircle(at(inner, half), at(inner, 0), at(inner, -half))])
        part = Face(sector).Extrude(high - low)
        part.solids.name = region
        part.faces.Min(Z).name, part.faces.Max(Z).name = bottom, top or "back"
        sides = [f for f in part.faces if f.name not in (bottom, top or "back")]
        ends = sorted((f for f in sides if abs(f.center.y) > 1e-9 * outer), key=lambda f: f.center.y)
        arcs = sorted((f for f in sides if abs(f.center.y) <= 1e-9 * outer), key=lambda f: f.mass)
        for face, name in zip([*ends, *arcs], ("leading", "trailing", "inner", "outer")):
            face.name = name
        if bottom == "contact":
            _refine_contact(part.faces.Min(Z), mesh)
        return part

    return _stacked(make, geometry, mesh, thickness)


register(Kind("pad", "`pad` an annular-sector brake pad r_i ≤ r ≤ r_o, |φ| ≤ angle/2, 0 ≤ z ≤ thickness (faces "
              "contact z = 0, back, inner, outer, leading φ = −angle/2, trailing)", 3, (0.6, 1.0, 60.0, 0.15),
              "`pad` [r_inner, r_outer, angle_deg, thickness]",
              ("contact", "back", "inner", "outer", "leading", "trailing"), check=_check_pad, extent=_pad_extent,
              build=_pad, options=("geometry.backing",), thickness=3))


# ---------------------------------------------------------------- pin


def _cap(radius: float, end_radius: float) -> float:
    """Height of the spherical cap of radius R over a disc of radius a."""
    return end_radius - math.sqrt(end_radius ** 2 - radius ** 2)


def _pin_defaults(g: dict) -> None:
    g.setdefault("position", [1.0, 0.0])
    g.setdefault("end", "flat")
    if g["end"] == "sphere" and isinstance(g.get("size"), list) and g["size"]:
        g.setdefault("end_radius", g["size"][0])


def _check_pin(g) -> None:
    radius, length = g.size
    if g.position is None or len(g.position) != 2:
        raise SceneError(f"geometry.position: must be a list of 2 numbers (got {list(g.position or ())})")
    check_features("geometry.size", g.size, {"shortest side": min(g.size)}, max(g.size))
    if g.end != "sphere":
        if g.end_radius is not None:
            raise SceneError("geometry.end_radius: only for geometry.end = 'sphere'")
        return
    largest = radius ** 2 / (2 * FEATURE * max(g.size)) + FEATURE * max(g.size) / 2   # where the cap is FEATURE thin
    if not radius <= g.end_radius <= largest:
        raise SceneError(f"geometry.end_radius: must be in [a, {largest:.4g}] (a = {radius}; a flatter cap cannot be "
                         f"meshed: use geometry.end = 'flat') (got {g.end_radius})")
    cap = _cap(radius, g.end_radius)
    if cap >= length:
        raise SceneError(f"geometry.size: the pin's length must exceed its cap's height {cap:.4g} (got {list(g.size)})")


def _pin(geometry, mesh):
    """A cylinder of radius a on the disc at ``position``, flat or with a spherical cap of radius R below.

    Its profile in a half-plane through the axis, revolved about the axis (robust, unlike booleans of
    a sphere and a cylinder): the axis, the back, the side down to the cap's rim, the end to the tip.
    A backing is the cylinder continued above the pin.
    """
    radius, length = geometry.size
    x, y = geometry.position

    def make(low, high, bottom, top, region):
        def at(r, z):
            return Pnt(x + r, y, z)

        cap, end = low, Segment(at(radius, low), at(0, low))
        if bottom == "contact" and geometry.end == "sphere":
            cap_radius = geometry.end_radius
            cap = _cap(radius, cap_radius)
            half = 0.5 * math.asin(radius / cap_radius)
            end = ArcOfCircle(at(radius, cap), at(cap_radius * math.sin(half), cap_radius * (1 - math.cos(half))),
                              at(0, 0))
        profile = Wire([Segment(at(0, low), at(0, high)), Segment(at(0, high), at(radius, high)),
                        Segment(at(radius, high), at(radius, cap)), end])
        part = Face(profile).Revolve(Axis(Pnt(x, y, 0), Z), 360)
        part.solids.name = region
        part.faces.name = "side"
        part.faces.Min(Z).name, part.faces.Max(Z).name = bottom, top or "back"
        if bottom == "contact":
            _refine_contact(part.faces.Min(Z), mesh)
        return part

    return _stacked(make, geometry, mesh, length)


register(Kind("pin", "`pin` a cylinder of radius a from z = 0 up to z = length (faces contact, back, side)", 3,
              (0.1, 0.3), "`pin` [a, length]", ("contact", "back", "side"), check=_check_pin,
              defaults=_pin_defaults, build=_pin, thickness=1,
              options=("geometry.position", "geometry.end", "geometry.end_radius", "geometry.backing")))
