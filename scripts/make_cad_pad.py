"""Write geometries/cad_pad.step: a brake pad as a CAD system would hand it over.

An annular-sector pad (r = 100 … 150 mm, 60°, 12 mm thick, SI units: metres) with a 2 mm chamfer
on its leading and trailing edges of the friction face and a radial wear-indicator slot (3 mm wide,
4 mm deep) across the friction face at φ = 0.  The faces are named in the file: ``contact`` (the
friction face, in two pieces either side of the slot), ``back``, ``inner``, ``outer``, ``leading``,
``trailing``, ``chamfer`` and ``slot``.  Run ``.venv/bin/python scripts/make_cad_pad.py``.
"""
import math
from pathlib import Path

from netgen.occ import Box, Cylinder, HalfSpace, Pnt, Vec, Z

INNER, OUTER, ANGLE, THICKNESS = 0.100, 0.150, 60.0, 0.012
CHAMFER, SLOT_WIDTH, SLOT_DEPTH = 0.002, 0.003, 0.004
HALF = math.radians(ANGLE) / 2


def pad():
    """Built by booleans, not by extrusion: every face its own geometry, so that STEP keeps every name."""
    ring = Cylinder(Pnt(0, 0, 0), Z, r=OUTER, h=THICKNESS) - Cylinder(Pnt(0, 0, -1), Z, r=INNER, h=THICKNESS + 2)
    # HalfSpace keeps the side away from its normal: the outward normals of the planes φ = ±angle/2
    sin, cos = math.sin(HALF), math.cos(HALF)
    body = ring * HalfSpace(Pnt(0, 0, 0), Vec(-sin, -cos, 0)) * HalfSpace(Pnt(0, 0, 0), Vec(-sin, cos, 0))
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


if __name__ == "__main__":
    target = Path(__file__).resolve().parents[1] / "geometries" / "cad_pad.step"
    shape = pad()
    shape.WriteStep(str(target))
    names = sorted({f.name for f in shape.faces})
    print(f"wrote {target} ({len(shape.faces)} faces: {', '.join(names)}; volume {shape.mass * 1e6:.3f} cm³)")
    assert {"contact", "back", "inner", "outer", "leading", "trailing", "chamfer", "slot"} == set(names)
