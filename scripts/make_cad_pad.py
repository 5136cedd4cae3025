"""Write geometries/cad_pad.step and geometries/cad_pad_backed.step: brake pads as a CAD system would hand them over.

cad_pad.step: an annular-sector pad (r = 100 … 150 mm, 60°, 12 mm thick, SI units: metres) with a 2 mm
chamfer on its leading and trailing edges of the friction face and a radial wear-indicator slot (3 mm wide,
4 mm deep) across the friction face at φ = 0.  The faces are named in the file: ``contact`` (the friction
face, in two pieces either side of the slot), ``back``, ``inner``, ``outer``, ``leading``, ``trailing``,
``chamfer`` and ``slot``.

cad_pad_backed.step: two named solids, glued (one face shared, so the mesh is conforming across it): that
friction block (solid ``friction``) on a 5.5 mm steel backing plate (solid ``steel``) that overhangs it by
5 mm at both radii and 3° at both ends, as real backing plates do.  Faces: those of the block (its back is
now the shared face, unnamed), the plate's ``back``, its rim ``plate_rim`` and the ring of its underside
around the block ``plate_underside``.

Run ``.venv/bin/python scripts/make_cad_pad.py``.
"""
import math
from pathlib import Path

from netgen.occ import Box, Cylinder, Glue, HalfSpace, Pnt, Vec, Z

INNER, OUTER, ANGLE, THICKNESS = 0.100, 0.150, 60.0, 0.012
CHAMFER, SLOT_WIDTH, SLOT_DEPTH = 0.002, 0.003, 0.004
HALF = math.radians(ANGLE) / 2
PLATE, OVERHANG, OVERHANG_ANGLE = 0.0055, 0.005, 3.0


def sector(inner, outer, half, low, high):
    """The annular sector inner ≤ r ≤ outer, |φ| ≤ half, low ≤ z ≤ high, by booleans (every face its own geometry)."""
    ring = Cylinder(Pnt(0, 0, low), Z, r=outer, h=high - low) - Cylinder(Pnt(0, 0, low - 1), Z, r=inner,
                                                                         h=high - low + 2)
    # HalfSpace keeps the side away from its normal: the outward normals of the planes φ = ±half
    sin, cos = math.sin(half), math.cos(half)
    return ring * HalfSpace(Pnt(0, 0, 0), Vec(-sin, -cos, 0)) * HalfSpace(Pnt(0, 0, 0), Vec(-sin, cos, 0))


def pad():
    """Built by booleans, not by extrusion: every face its own geometry, so that STEP keeps every name."""
    body = sector(INNER, OUTER, HALF, 0.0, THICKNESS)
    ends = [e for e in body.edges if abs(e.center.z) < 1e-12 and abs(math.atan2(e.center.y, e.center.x)) > 0.9 * HALF]
    body = body.MakeChamfer(ends, CHAMFER)
    slot = Box(Pnt(INNER - 0.01, -SLOT_WIDTH / 2, -0.001), Pnt(OUTER + 0.01, SLOT_WIDTH / 2, SLOT_DEPTH))
    body = body - slot
    for face in body.faces:
        c = face.center
        radius, phi = math.hypot(c.x, c.y), math.atan2(c.y, c.x)
        if abs(c.z) < 1e-9:
            face.name = "contact"
        elif abs(c.z - THICKNESS) < 1e-9:
            face.name = "back"
        elif abs(c.y) < SLOT_WIDTH and c.z < SLOT_DEPTH + 1e-9:
            face.name = "slot"
        elif c.z < CHAMFER and abs(phi) > 0.8 * HALF:
            face.name = "chamfer"
        elif abs(phi) > 0.9 * HALF:
            face.name = "leading" if phi < 0 else "trailing"
        else:
            face.name = "inner" if radius < (INNER + OUTER) / 2 else "outer"
    body.solids.name = "pad"
    return body


def backed():
    """The pad (solid ``friction``) glued onto its steel backing plate (solid ``steel``)."""
    block = pad()
    block.solids.name = "friction"
    plate = sector(INNER - OVERHANG, OUTER + OVERHANG, HALF + math.radians(OVERHANG_ANGLE), THICKNESS,
                   THICKNESS + PLATE)
    plate.solids.name = "steel"
    for face in plate.faces:
        z = face.center.z
        face.name = ("back" if abs(z - THICKNESS - PLATE) < 1e-9 else "plate_underside" if abs(z - THICKNESS) < 1e-9
                     else "plate_rim")
    shared = next(face for face in block.faces if face.name == "back").mass
    part = Glue([block, plate])
    for face in part.faces:       # the shared face (the block's back): inside the part, no boundary
        if abs(face.center.z - THICKNESS) < 1e-9 and abs(face.mass - shared) < 1e-9 * shared:
            face.name = None
    return part


if __name__ == "__main__":
    folder = Path(__file__).resolve().parents[1] / "geometries"
    shape = pad()
    shape.WriteStep(str(folder / "cad_pad.step"))
    names = sorted({f.name for f in shape.faces})
    print(f"wrote cad_pad.step ({len(shape.faces)} faces: {', '.join(names)}; volume {shape.mass * 1e6:.3f} cm³)")
    assert {"contact", "back", "inner", "outer", "leading", "trailing", "chamfer", "slot"} == set(names)
    shape = backed()
    shape.WriteStep(str(folder / "cad_pad_backed.step"))
    names = sorted({f.name for f in shape.faces if f.name})
    solids = [f"{s.name} {s.mass * 1e6:.3f} cm³" for s in shape.solids]
    print(f"wrote cad_pad_backed.step ({len(shape.faces)} faces: {', '.join(names)}; solids {', '.join(solids)})")
    assert {"contact", "back", "inner", "outer", "leading", "trailing", "chamfer", "slot", "plate_rim",
            "plate_underside"} == set(names)
