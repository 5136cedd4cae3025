r"""
Work against precision: which time integrator to use
====================================================

The wear law :math:`w' = \alpha\,p(u_\nu - w)` is integrated in time by one of three rules, at the contact points,
with :math:`p_j = p(u_{\nu,j} - w_j)`:

.. math::

   \text{explicit (the paper's eq. 15):}\quad & w_{j+1} = w_j + k\,\alpha\,p_j, \\
   \text{implicit (backward Euler):}\quad & w_{j+1} = w_j + k\,\alpha\,p_{j+1}, \\
   \text{trapezoidal:}\quad & w_{j+1} = w_j + \tfrac{k}{2}\,\alpha\,(p_j + p_{j+1}),

of orders 1, 1 and 2 in :math:`k`.  Each step solves the contact problem once whichever rule is used, so the
cost of a run is its number of steps, and the second-order rule reaches a given accuracy far cheaper.  We
measure the wear error at :math:`T` in :math:`L^2(\Gamma_C)` against a run with 640 trapezoidal steps on the same
mesh (so that only the time error is left), together with the wall time of each run (all on the reference's
factorisation), and add error-controlled steps (``time.adaptive``), which choose :math:`k` from an estimate of the
local error.
"""

# %%
from pathlib import Path

from matplotlib.figure import Figure

import ngwear
from ngwear.model.examples import scene_file
from ngwear.studies import verify

scene = ngwear.load_scene(scene_file("paper_strip")).replace(**{"mesh.maxh": 0.2, "output.every": 1.0})
steps = [20, 40, 80, 160]
studies = {rule: verify.k_study(scene.replace(**{"wear.integrator": rule}), steps, 640)
           for rule in ("explicit", "implicit", "trapezoidal")}
for rule, rows in studies.items():
    print(f"{rule:12}", "  ".join(f"{r['steps']:4d} steps {r['W_final']:.2e} in {r['seconds'] * 1e3:4.0f} ms"
                                  for r in rows), f"  order {verify.orders(rows, 'k')['W_final']:.2f}")

# %%
# Error-controlled steps with the trapezoidal rule, at three tolerances (the wear error to meet at :math:`T`,
# relative to :math:`g`), against the same reference.
reference, _ = verify._run(scene.replace(**{"time.steps": 640, "wear.integrator": "trapezoidal"}))
adaptive = []
for tolerance in (1e-2, 1e-3, 1e-4):
    run, seconds = verify._run(scene.replace(**{"time.adaptive": True, "time.tolerance": tolerance,
                                                "wear.integrator": "trapezoidal"}), like=reference)
    adaptive.append({"steps": run.steps, "seconds": seconds, **verify.errors(run, reference).__dict__})
    print(f"tolerance {tolerance:.0e}: {run.steps} steps, wear error {adaptive[-1]['W_final']:.2e}")

# %%
fig = Figure(figsize=(11, 4), layout="constrained")
left, right = fig.subplots(1, 2)
for rule, rows in {**studies, "adaptive trapezoidal": adaptive}.items():
    style = "s--" if rule.startswith("adaptive") else "o-"
    left.loglog([r["steps"] for r in rows], [r["W_final"] for r in rows], style, label=rule)
    right.loglog([r["seconds"] for r in rows], [r["W_final"] for r in rows], style, label=rule)
left.set(xlabel="time steps", ylabel="wear error at T in L²(Γ_C)", title="error against steps")
right.set(xlabel="wall time [s]", title="error against wall time")
for ax in (left, right):
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
(Path("out") / "work_precision").mkdir(parents=True, exist_ok=True)
fig.savefig(Path("out") / "work_precision" / "work_precision.png", dpi=100)

# %%
# The observed orders, least-squares slopes of :math:`\log E` against :math:`\log k`:
orders = {rule: verify.orders(rows, "k")["W_final"] for rule, rows in studies.items()}
print(", ".join(f"{rule} {order:.2f}" for rule, order in orders.items()))
