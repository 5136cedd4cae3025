r"""
A brake pad wearing in: torque and p·r
======================================

A pad (annular sector :math:`r_i = 100` mm to :math:`r_o = 150` mm, 60°, friction material on a steel backing
plate) is pressed by the caliper's rigid piston with :math:`F = 3` kN onto a disc turning at
:math:`\omega = 50` rad/s, :math:`\mu = 0.4`.  At every contact point the foundation moves with
:math:`\boldsymbol v^* = \boldsymbol\omega \times \boldsymbol x`, so the wear rate
:math:`w' = \kappa\,\omega r\, p` grows with the radius :math:`r`.  A new pad presses uniformly,
:math:`p = F/A`, and brakes with the torque

.. math::

   T_{\text{new}} = \mu \int_{\Gamma_C} p\, r \,\mathrm da
   = \frac{2}{3}\,\mu F\,\frac{r_o^3 - r_i^3}{r_o^2 - r_i^2} = 152.0\ \text{N·m}.

Once worn in, every point in contact wears at the plate's speed :math:`\delta'`: :math:`\kappa\omega r p = \delta'`,
so :math:`p\cdot r` is constant over the face, :math:`p = F / (r \int_{\Gamma_C} r^{-1}\,\mathrm da)`, and the
torque becomes the uniform-wear value of disc-brake design

.. math::

   T_{\text{worn}} = \mu F\, \frac{\int_{\Gamma_C} \mathrm da}{\int_{\Gamma_C} r^{-1}\,\mathrm da}
   = \mu F\, \frac{r_i + r_o}{2} = 150\ \text{N·m}.

The transient decays like :math:`e^{-\kappa\omega r L t}`, a few :math:`\tau = 1/(\kappa\omega r L) \approx 20` s
for the shipped scene (``geometries/brake_pad.toml``), which runs for 150 s.
"""

# %%
from pathlib import Path

import numpy as np

import ngwear
from ngwear.model.examples import scene_file
from ngwear.views.pictures import write_pictures

scene = ngwear.load_scene(scene_file("brake_pad"))
result = ngwear.simulate(scene, progress=False)
mu, force = scene.contact.friction, -scene.loads.plate.force[2]
r_i, r_o = scene.geometry.size[:2]
new = 2 / 3 * mu * force * (r_o ** 3 - r_i ** 3) / (r_o ** 2 - r_i ** 2)
worn = mu * force * (r_i + r_o) / 2
print(f"braking torque: {-result.torque[0]:.2f} N·m new (uniform pressure: {new:.2f}), "
      f"{-result.torque[-1]:.2f} N·m at t = {result.times[-1]:g} s (uniform wear: {worn:.2f})")

# %%
# The pictures: the pad from the disc's side at four times, maps of pressure and wear on the friction face,
# the force, torque, worn volume and plate displacement over time, and :math:`p\cdot r` against the radius,
# which flattens as the pad wears in.
pictures = write_pictures(result, Path("out") / scene.name)

# %%
# How flat :math:`p\cdot r` has become: its spread over the face, relative to its mean, at the first and last step.
r = np.linalg.norm(result.contact_points[:, :2], axis=1)
for step in (0, -1):
    pr = result.pressure[step] * r
    print(f"t = {result.times[step]:5.1f} s: spread of p·r {np.std(pr) / np.mean(pr):.1e}")
