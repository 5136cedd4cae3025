r"""
A parameter study on Dask
=========================

How do the friction coefficient :math:`\mu` and the wear coefficient :math:`\kappa` change the wear of the paper's
strip?  A study file names a base scene and the keys to vary; ``ngwear.sweep`` runs every case on a Dask cluster
(by default a local one, one worker process per core) and returns a table.  Cases that share a mesh and a
material share one factorisation per worker.  We read the shipped study (16 cases on a 4 × 4 grid) and run it
coarser, so that it takes seconds:

.. code-block:: toml

   # geometries/studies/friction_wear.toml
   name = "friction_wear"
   scene = "../paper_strip.toml"
   [set]
   "mesh.maxh" = 0.1
   "time.steps" = 50
   [grid]
   "contact.friction" = [0.0, 0.5, 1.0, 1.5]
   "contact.wear" = [0.5, 1.0, 1.5, 2.0]

Every case is an ordinary run: its maximum wear is the one ``simulate`` computes for the same scene, which the
last cell checks.
"""

# %%
# A cluster: a scheduler and two single-threaded workers, started with the ``dask`` command line as on the
# machines of a real cluster (``dask scheduler`` on one, ``dask worker ADDRESS`` on the others).  Without a
# ``client``, ``ngwear.sweep`` starts a local cluster itself (``ngwear sweep STUDY.toml`` does that).
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import ngwear
import ngwear.studies.sweep
from ngwear.model.examples import FOLDER

out = Path("out") / "friction_wear"
shutil.rmtree(out, ignore_errors=True)      # a re-run into the same folder would only run the missing cases
out.mkdir(parents=True)
dask = [sys.executable, "-m", "dask"]
cluster = [subprocess.Popen([*dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                             "--scheduler-file", str(out / "scheduler.json")], stderr=subprocess.DEVNULL)]
while not (out / "scheduler.json").is_file():
    time.sleep(0.1)
address = json.loads((out / "scheduler.json").read_text())["address"]
cluster += [subprocess.Popen([*dask, "worker", address, "--nthreads", "1", "--no-dashboard"], stderr=subprocess.DEVNULL)
            for _ in range(2)]
print("scheduler at", address)

# %%
# The study, its table and the plots ``ngwear sweep`` writes into ``out/friction_wear/plots/``: each output
# against each varied key (one line per value of the other key), and a heat map of the two-key grid.
try:
    table = ngwear.sweep(FOLDER / "studies" / "friction_wear.toml", address, out=out, workers=2, progress=False,
                         overrides={"mesh.maxh": 0.2, "time.steps": 20})
finally:
    for process in cluster:
        process.terminate()
        process.wait()
print(table[["contact.friction", "contact.wear", "max_wear", "worn_volume", "max_pressure", "status"]]
      .to_string(index=False))
print(ngwear.studies.sweep.summary_text(table.attrs["summary"]))

# %%
# One case against a direct run of the same scene.
case = table.iloc[5]
scene = ngwear.load_scene(FOLDER / "paper_strip.toml").replace(**{
    "mesh.maxh": 0.2, "time.steps": 20, "contact.friction": case["contact.friction"],
    "contact.wear": case["contact.wear"]})
direct = ngwear.simulate(scene, progress=False)
print(f"case {case['case']}: max wear {case['max_wear']:.12g} in the study, {direct.wear.max():.12g} run directly")
