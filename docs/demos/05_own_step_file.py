r"""
Your own part from a STEP file
==============================

Any solid whose faces carry names can be simulated: ``geometry.kind = "step"`` reads a STEP (or IGES, BREP)
file, its face names are the boundaries, and one of them must be ``contact`` (:math:`\Gamma_C`).  Here we make
a part as a CAD system would hand it over — a 40 × 20 × 10 mm block with chamfered leading and trailing edges —
write it as STEP, and press it with a rigid plate on its ``back`` face (:math:`F = 500` N) onto a counterface
sliding at :math:`v = 0.5` m/s.

With a translating counterface every contact point slides at the same speed, so the worn volume
:math:`V = \int_{\Gamma_C} w\,\mathrm da` grows at :math:`\kappa v \int_{\Gamma_C} p\,\mathrm da = \kappa v F`
while the layer carries the whole force (no point reaches :math:`u_\nu = g`), whatever the pressure's shape:

.. math::

   V(T) = \kappa\, v\, F\, T .

The shipped ``cad_pad.step`` (the brake pad of the previous example with chamfers and a wear-indicator slot) is
run the same way by ``ngwear run geometries/cad_pad.toml``.
"""

# %%
# The part, with netgen's OCC interface (any CAD system that writes STEP with face names does the same).
from pathlib import Path

from netgen.occ import Box, Pnt

import ngwear
from ngwear.views.pictures import write_pictures

out = Path("out") / "block"
out.mkdir(parents=True, exist_ok=True)
block = Box(Pnt(0, 0, 0), Pnt(0.040, 0.020, 0.010))
block = block.MakeChamfer([e for e in block.edges if e.center.z < 1e-9 and abs(e.center.y - 0.010) < 1e-9], 0.002)
for face in block.faces:
    c = face.center
    face.name = "contact" if c.z < 1e-9 else "back" if c.z > 0.010 - 1e-9 else "chamfer" if c.z < 0.002 else "side"
block.WriteStep(str(out / "block.step"))
print(sorted({face.name for face in block.faces}))

# %%
# A scene file beside it: the part file is found relative to the scene file.
(out / "block.toml").write_text('''
name = "block"
[geometry]
kind = "step"
file = "block.step"
dirichlet = []            # held by the plate alone
[mesh]
maxh = 0.004
[material]
young = 1.0e9
poisson = 0.3
[contact]
stiffness = 1.0e10        # L [Pa/m]
gap = 1.0e-3              # g: a 1 mm layer
friction = 0.3
wear = 1.0e-10            # κ [1/Pa]
direction = [0.0, 0.0, -1.0]
[foundation]
velocity = [0.5, 0.0, 0.0]
[loads]
plate = { boundary = "back", force = [0.0, 0.0, -500.0] }
[time]
T = 10.0
steps = 20
''')
scene = ngwear.load_scene(out / "block.toml")
result = ngwear.simulate(scene, progress=False)
kappa, speed, force, T = scene.contact.wear, 0.5, 500.0, scene.time.T
print(f"worn volume {result.wear_volume[-1] * 1e9:.4f} mm³, κ v F T = {kappa * speed * force * T * 1e9:.4f} mm³; "
      f"max wear {result.wear.max() * 1e3:.3f} mm of g = 1 mm; reaction max {result.reaction.max():.1e} Pa")

# %%
# Its pictures, as ``ngwear run`` writes them.
pictures = write_pictures(result, out)
