r"""
A pin on a disc against Archard's law
=====================================

The pin-on-disc test (ASTM G99 style): a pin of radius :math:`a = 3` mm with a spherical end (radius 5 mm) at
:math:`R = 30` mm from the axis of a disc turning at :math:`\omega = 10` rad/s, pressed with :math:`F = 10` N.
Archard's law says the worn volume grows at

.. math::

   \frac{\mathrm dV}{\mathrm dt} = \kappa\, \|\boldsymbol v^*\|\, F = \kappa\,\omega R\, F,

for a sliding speed :math:`\omega R`.  In ngwear the worn volume is :math:`V = \int_{\Gamma_C} w\,\mathrm da`
and :math:`w' = \kappa\,\omega r\,p`: once the pin has worn in, :math:`p\cdot r` is constant where it touches
(every point there wears at the same rate) and :math:`V' = \kappa\omega F R_{\text{eff}}` with
:math:`R_{\text{eff}} = \int \mathrm da / \int r^{-1}\mathrm da` over the contact area: for a flat end of radius
:math:`a`, :math:`R\,(1 - a^2/(8R^2) + \dots)`, Archard's rate to :math:`(a/R)^2/8 = 0.13\,\%`.  The spherical end
first touches in a point and wears a growing flat around it, smaller than the pin's face in this minute of sliding,
so :math:`R_{\text{eff}}` is closer still to :math:`R`.
"""

# %%
from pathlib import Path

import numpy as np

import ngwear
from ngwear.model.examples import scene_file
from ngwear.views.pictures import write_pictures

scene = ngwear.load_scene(scene_file("pin_on_disc"))
result = ngwear.simulate(scene, progress=False)
kappa, omega = scene.contact.wear, scene.foundation.angular_velocity[2]
radius, force = scene.geometry.position[0], -scene.loads.plate.force[2]
archard = kappa * omega * radius * force
rate = np.diff(result.wear_volume) / np.diff(result.times)
print(f"worn-volume rate at the end {rate[-1]:.4e} m³/s, Archard κωRF = {archard:.4e} m³/s "
      f"({rate[-1] / archard - 1:+.2%})")
print(f"contact area {result.contact_area[0] * 1e6:.2f} mm² at the start, {result.contact_area[-1] * 1e6:.2f} mm² "
      f"at the end (the pin's face: {np.pi * 3 ** 2:.2f} mm²)")

# %%
# The pictures: the pin at four times, the contact face's pressure and wear, the history (the worn volume
# grows linearly once the flat covers the face) and p·r over the radius.
pictures = write_pictures(result, Path("out") / scene.name)
