r"""
Convergence in space: observed orders against the paper's error estimate
========================================================================

Theorem 5 of Jureczka & Ochal bounds the error of the fully discrete scheme with P1 elements, for a solution
:math:`\boldsymbol u \in C([0,T]; H^2(\Omega)^d)`, by

.. math::

   k \sum_{j=1}^{N} \Big( \|\boldsymbol u_j - \boldsymbol u_j^{hk}\|_V^2 + \|w_j - w_j^{hk}\|_{W}^2 \Big)
   \le \tilde c\,\big(k^2 + k h^2 + h\big),
   \qquad \|\boldsymbol v\|_V = \|\boldsymbol\varepsilon(\boldsymbol v)\|_{L^2(\Omega)},\quad W = L^2(\Gamma_C),

so the summed error is at least :math:`O(h^{1/2})`.  P1 elements approximate :math:`\boldsymbol\varepsilon(\boldsymbol u)`
of a smooth solution at order 1, and that is what the displacement shows here: the paper's scene with 20 steps at
``mesh.maxh`` 0.4, 0.2 and 0.1 against a fine run at 0.025 (``ngwear verify`` does the same at more sizes).
The orders are least-squares slopes of :math:`\log E` against :math:`\log h`.
"""

# %%
from pathlib import Path

import ngwear
from ngwear.model.examples import scene_file
from ngwear.studies import verify
from ngwear.views import plots

scene = ngwear.load_scene(scene_file("paper_strip")).replace(**{"time.steps": 20})
rows = verify.h_study(scene, [0.4, 0.2, 0.1], 0.025)
print(verify.markdown(rows, "h"))

# %%
# ``V_sum`` and ``W_sum`` are the two terms of the left-hand side above, ``V_final`` and ``W_final`` the
# errors at :math:`T`.  The wear converges faster than the estimate's :math:`h^{1/2}`: it is an integral in
# time of the pressure, which is smoother than the displacement's gradient.
orders = verify.orders(rows, "h")
plots.convergence({"P1": rows}, "h", Path("out") / "convergence" / "convergence_h.png")
print(f"observed orders: V_sum {orders['V_sum']:.2f}, W_sum {orders['W_sum']:.2f}")
