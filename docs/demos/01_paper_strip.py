r"""
The paper's scene: a strip pressed on a moving foundation (Figs. 1–4)
=====================================================================

Section 5 of Jureczka & Ochal: the strip :math:`\Omega = [0,3]\times[0,1]`, clamped on :math:`x = 0`, pressed
by :math:`\boldsymbol f_N = (0, -0.1)` on its top and right edges onto a rigid foundation that slides with
:math:`\boldsymbol v^* = (1, 0)` under its bottom edge :math:`\Gamma_C`, covered by a soft layer of thickness
:math:`g = 0.2`.  With :math:`\lambda = \eta = 1`, :math:`p(r) = 10\,r_+`, :math:`\mu = 1`, :math:`\kappa = 1.5`
and :math:`T = 1`, the displacement :math:`\boldsymbol u` and the wear :math:`w` solve

.. math::

   -\operatorname{Div}\boldsymbol\sigma(\boldsymbol u) = 0, \qquad
   u_\nu \le g, \qquad
   -\boldsymbol\sigma_\tau = \mu\, p(u_\nu - w)\,\boldsymbol n^*, \qquad
   w' = \kappa \|\boldsymbol v^*\|\, p(u_\nu - w), \quad w(0) = 0,

and the paper's explicit scheme (eq. 15) updates the wear at the contact points
:math:`w_{j+1} = w_j + k\,\alpha\, p_j` with :math:`\alpha = \kappa\|\boldsymbol v^*\|`.  Summed with the
points' weights :math:`m_i` this is the discrete Archard law: the worn area grows by
:math:`k\,\alpha\sum_i m_i p_{j,i}` per step, which this example checks to round-off.
"""

# %%
# Load the shipped scene (package data: ``geometries/paper_strip.toml`` in the repository) and run it,
# as ``ngwear run paper_strip.toml`` does.
from pathlib import Path

import numpy as np

import ngwear
from ngwear.model.examples import scene_file
from ngwear.views.pictures import write_pictures

scene = ngwear.load_scene(scene_file("paper_strip"))
result = ngwear.simulate(scene, progress=False)
print(result.status, "after", result.steps, "steps of k =", scene.time.T / scene.time.steps)
for key, value in result.summary().items():
    print(f"{key:24} {value}")

# %%
# The pictures ``ngwear run`` writes beside the results: the body after 25, 50, 75 and 100 steps as in
# the paper's Figs. 1–4 (body coloured by the displacement, the soft layer by the wear, its worn-away
# part light grey, the foundation moving right), the wear profiles along :math:`\Gamma_C`, the pressure
# and the history of force, torque and worn area.
out = Path("out") / scene.name
pictures = write_pictures(result, out)
print("\n".join(p.name for p in pictures))

# %%
# The discrete Archard law: the worn area :math:`\sum_i m_i w_{N,i}` equals
# :math:`k\,\alpha \sum_{j<N}\sum_i m_i p_{j,i}`, computed here from the pressures alone.
k = scene.time.T / scene.time.steps
alpha = scene.contact.wear * np.linalg.norm(scene.foundation.velocity)
archard = k * alpha * (result.pressure[:-1] @ result.weights).sum()
worn = result.wear_volume[-1]
print(f"worn area {worn:.12f}, k α Σ m p = {archard:.12f}, relative difference {abs(worn - archard) / archard:.1e}")
