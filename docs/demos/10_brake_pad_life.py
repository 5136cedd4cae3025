r"""
A brake pad's life: 1 600 stops, half the friction material
===========================================================

The shipped pad (``geometries/brake_pad.toml``: 12 mm of friction material on a steel backing plate, pressed by a
rigid piston on a disc turning at up to 50 rad/s) through a wear-test-like programme
(``geometries/brake_pad_life.toml``): 400 stops to rest from 50 rad/s at 3 kN, 400 from 30 rad/s at 4.5 kN, 800
from 50 rad/s with the pressure rising from 1.5 to 3 kN, each stop followed by 30 s of cooling.

The worn material leaves the body (``wear.geometry = "surface"``): once the wear since the last update reaches a
quarter of the layer, the friction face moves into the pad by it and the discretization is rebuilt on the moved
mesh.  Stops whose wear increments have settled are applied many at once (``programme.jump``): a jump of N stops
adds N times the last stop's increment, N bounded so that the pressure changes by at most 1 % over it (see
*A part's life* in the guide).  ``wear.limit`` (2 mm of friction material left) would end the run as worn out.

Worn in, every point wears at the piston's speed, so the wear per stop is uniform over the face and
:math:`p\,r` is constant: the torque is the uniform-wear value :math:`\mu F (r_i + r_o)/2` at the load of the
moment.
"""

# %%
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import ngwear
from ngwear.model.examples import scene_file
from ngwear.model.programme import Schedule
from ngwear.results.metrics import per_block

scene = ngwear.load_scene(scene_file("brake_pad_life"))
result = ngwear.simulate(scene, progress=False)
stops = result.stops
out = Path("out") / scene.name
out.mkdir(parents=True, exist_ok=True)
total = result.total_wear[-1]
print(f"{result.status}: {len(stops)} stops, {int(stops['simulated'].sum())} simulated, "
      f"{result.geometry_updates} geometry updates; worn up to {1e3 * total.max():.2f} mm of "
      f"{1e3 * result.thickness.max():.0f} mm; {result.wall_time:.1f} s")

# %%
# The remaining thickness over the friction face at the end: within 0.02 mm of uniform.  Worn in, every point
# wears alike; what differs is the imprint of the running-in of each block (the outer radius, which slides fastest,
# wears more until p·r is constant: the radial taper below).
x, y = result.contact_points[:, 0], result.contact_points[:, 1]
figure, axes = plt.subplots(figsize=(6, 4.5))
shown = axes.tricontourf(1e3 * x, 1e3 * y, 1e3 * result.remaining_thickness[-1], levels=20)
figure.colorbar(shown, label="remaining friction material [mm]")
axes.set(xlabel="x [mm]", ylabel="y [mm]", aspect="equal", title="remaining thickness at the end")
figure.savefig(out / "thickness_map.png", dpi=100)

# %%
# Taper against stops: ``Result.stops`` (and ``stops.csv``) holds at the end of each stop, simulated or jumped, the
# radial (outer minus inner) and circumferential (leading minus trailing) taper of the remaining thickness, from the
# fit t ≈ a + b r + c φ over the face.  Each block starts with a running-in at its own load (the layer's compression
# changes): the outer radius, which slides fastest, wears more until p·r is constant; then the taper stays.
figure, axes = plt.subplots(figsize=(6, 4))
axes.plot(stops.index, 1e3 * stops["taper_radial"], label="radial (outer − inner)")
axes.plot(stops.index, 1e3 * stops["taper_circumferential"], label="circumferential (leading − trailing)")
axes.set(xlabel="stop", ylabel="taper of the remaining thickness [mm]", title="taper against stops")
axes.legend()
figure.savefig(out / "taper.png", dpi=100)

# %%
# Wear per block: per stop and per MJ dissipated.  The worn volume per MJ is the same in every block, κ/μ (Archard's
# law against the friction power), whatever the speed and load of its stops.
blocks = per_block(stops["block"].to_numpy(), stops["worn_volume"].to_numpy(), stops["energy"].to_numpy())
for b, (count, per_stop, per_mj) in enumerate(zip(blocks["stops"], blocks["volume_per_stop"],
                                                  blocks["volume_per_megajoule"])):
    print(f"block {b}: {count} stops, {1e9 * per_stop:.2f} mm³ per stop, {1e9 * per_mj:.1f} mm³ per MJ")
figure, axes = plt.subplots(figsize=(6, 4))
axes.bar(range(len(blocks["stops"])), 1e9 * blocks["volume_per_stop"])
axes.set(xlabel="block", ylabel="worn volume per stop [mm³]", title="wear per block")
figure.savefig(out / "wear_per_block.png", dpi=100)

# %%
# Worn in: the last simulated stop's wear increment over the face, and the braking torque at its start against
# μ F (r_i + r_o)/2 at the stop's load factor.
schedule = Schedule.of(scene.programme)
stop_of, step_of = schedule.rows(result.jumped)
wear = result.total_wear
last = np.flatnonzero(step_of[:result.steps + 1] == scene.programme.steps_per_stop)[-1]
increment = wear[last] - wear[last - scene.programme.steps_per_stop]
spread = np.ptp(increment) / (result.weights @ increment / result.weights.sum())
r_i, r_o = scene.geometry.size[:2]
start = last - scene.programme.steps_per_stop
force = -scene.loads.plate.force[2] * schedule.load[stop_of[last], 0]
uniform = scene.contact.friction * force * (r_i + r_o) / 2
print(f"last stop: wear increment spread {100 * spread:.2f} % over the face; torque {-result.torque[start]:.2f} N·m "
      f"(uniform wear: {uniform:.2f} N·m)")
