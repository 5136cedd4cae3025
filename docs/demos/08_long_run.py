r"""
A long run, interrupted and resumed
===================================

Wear is slow, so runs are long, and long runs get interrupted: Ctrl-C, a batch scheduler's time limit (SIGTERM),
a machine that goes down.  ``ngwear run`` stops at the next step boundary and writes every completed step; with
an output folder it also writes checkpoints (``checkpoint.npz``, every ``output.checkpoint_seconds`` of wall
time, at an interrupt and at the end), from which ``ngwear run --resume OUTDIR`` goes on.  A resumed run computes
the same numbers, to the last bit, as one that never stopped: every step starts from values the checkpoint holds
exactly.

In Python the same is ``simulate(scene, checkpoint=folder, stop=event)`` and ``simulate(None, resume=folder)``;
the command line's signal handler does nothing but set such an event.  Here a thread plays the part of a batch
scheduler that ends the job soon after it has written its first checkpoint: the paper's scene with 4 000 implicit
steps (:math:`w_{j+1} = w_j + k\,\alpha\,p(u_{\nu,j+1} - w_{j+1})`) and a checkpoint every 0.1 s.
"""

# %%
import shutil
import threading
import time
from pathlib import Path

import numpy as np

import ngwear
from ngwear.model.examples import scene_file

out = Path("out") / "long_run"
shutil.rmtree(out, ignore_errors=True)
out.mkdir(parents=True)
scene = ngwear.load_scene(scene_file("paper_strip")).replace(**{
    "mesh.maxh": 0.2, "time.steps": 4_000, "wear.integrator": "implicit", "output.checkpoint_seconds": 0.1})
stop = threading.Event()


def scheduler():
    while not (out / "checkpoint.npz").exists():
        time.sleep(0.01)
    stop.set()


threading.Thread(target=scheduler, daemon=True).start()
part = ngwear.simulate(scene, progress=False, checkpoint=out, stop=stop)
print(f"{part.status} after step {part.steps} of {scene.time.steps} (t = {part.times[-1]:.4f})")
print("in the folder:", ", ".join(sorted(p.name for p in out.iterdir())))

# %%
# Resumed from the folder alone (its mesh, its scene, its steps), then compared with a run that never stopped.
resumed = ngwear.simulate(None, progress=False, resume=out)
whole = ngwear.simulate(scene, progress=False)
same = all(np.array_equal(getattr(resumed, name), getattr(whole, name))
           for name in ("times", "wear", "normal_displacement", "pressure", "reaction"))
print(f"resumed: {resumed.status}, {resumed.steps} steps; bit for bit the uninterrupted run: {same}")
print(f"largest difference of the wear: {np.abs(resumed.wear - whole.wear).max():.1e}")

# %%
# The resumed run's wear over time: the first part was computed before the interrupt, the rest after it.
from matplotlib.figure import Figure

fig = Figure(figsize=(7, 3.5), layout="constrained")
ax = fig.add_subplot()
ax.plot(resumed.times, resumed.wear.max(axis=1), label="max wear w (resumed run)")
ax.plot(resumed.times, resumed.wear_volume, label="worn area Σ m w")
ax.axvline(part.times[-1], color="black", ls="--", lw=1, label=f"interrupted at t = {part.times[-1]:.3f}")
ax.set(xlabel="time t", title=f"{scene.time.steps} implicit steps, interrupted and resumed")
ax.legend(fontsize=8)
fig.savefig(out / "resumed.png", dpi=100)

# %%
# A finished run can also be extended to a later final time (the step k is kept):
# ``ngwear run --resume OUTDIR --set time.T=2 time.steps=8000``, in Python
# ``simulate(scene.replace(**{"time.T": 2.0, "time.steps": 8_000}), resume=out)``.  Any other change of the scene
# is refused, naming the keys that differ.
try:
    ngwear.simulate(scene.replace(**{"contact.friction": 0.5}), progress=False, resume=out)
except ngwear.SceneError as err:
    print("refused:", err)
