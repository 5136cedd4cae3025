r"""
A brake pad heating through three stops: temperatures, fade, wear against temperature
=====================================================================================

The shipped pad (``geometries/brake_pad_heat.toml``) brakes a grey-iron disc from 50 rad/s to rest three times,
30 s apart, with 3 kN.  Friction turns :math:`q = \mu p \lVert\boldsymbol v^*\rVert` into heat at the face; the pad
takes the share of Charron's partition,

.. math::

   \eta = \frac{e_b}{e_b + e_d},\qquad e = \sqrt{k\rho c},

about 15 % against grey iron; the disc, a lumped thermal mass :math:`C_d`, takes the rest and cools with
:math:`H_d`.  The friction fades above 120 °C, :math:`\mu = 0.42 - 0.0008\,(T - 120)_+`, and the wear coefficient
rises, :math:`\kappa = 8\cdot 10^{-13}(1 + e^{(T - 150)/30})`: both are read at each step from the last step's
surface temperature.  See the user guide's *Heat*.
"""

# %%
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

import ngwear
from ngwear.model.examples import scene_file
from ngwear.views import part_plots

scene = ngwear.load_scene(scene_file("brake_pad_heat"))
result = ngwear.simulate(scene, progress=False)
face = result.surface_temperature @ result.weights / result.weights.sum()      # the face's mean temperature
print(f"highest pad temperature {result.max_temperature.max():.0f} °C at t = "
      f"{result.times[np.argmax(result.max_temperature)]:.1f} s, disc {result.foundation_temperature.max():.1f} °C")

# %%
# Each stop: its peak face temperature, its mean braking torque and the volume it wore.
starts = [0.0, 30.0, 60.0]
stops = []
for start in starts:
    braking = (result.times > start) & (result.times <= start + 8.0)
    first, last = np.flatnonzero(braking)[[0, -1]]
    stops.append({"peak": face[braking].max(), "torque": -result.torque[braking].mean(),
                  "worn": result.wear_volume[last] - result.wear_volume[first - 1]})
    print(f"stop at {start:4.0f} s: face up to {stops[-1]['peak']:.0f} °C, mean torque {stops[-1]['torque']:.1f} N·m, "
          f"worn {stops[-1]['worn'] * 1e9:.2f} mm³")

# %%
# The pictures: temperatures of pad and disc, the torque fading as the face heats, wear per stop against its
# peak temperature (the table of a wear-versus-temperature test); then the run's own temperature pictures: the
# surface temperature along Γ_C and over time, and maps of pressure, wear and temperature on the face.
out = Path("out") / scene.name
fig = Figure(figsize=(12, 3.6), layout="constrained")
left, middle, right = fig.subplots(1, 3)
left.plot(result.times, result.max_temperature, label="pad, highest")
left.plot(result.times, face, label="pad face, mean")
left.plot(result.times, result.foundation_temperature, label="disc (lumped)")
left.set(xlabel="time t (s)", ylabel="temperature (°C)", title="temperatures")
left.legend(fontsize=8)
middle.plot(result.times, -result.torque)
middle.set(xlabel="time t (s)", ylabel="braking torque (N·m)", title="torque: fades as the face heats")
right.plot([s["peak"] for s in stops], [s["worn"] * 1e9 for s in stops], "o-")
right.set(xlabel="peak face temperature of the stop (°C)", ylabel="worn volume (mm³)", title="wear per stop")
out.mkdir(parents=True, exist_ok=True)
fig.savefig(out / "heat.png", dpi=110)
pictures = [part_plots.temperatures(result, out / "temperatures.png"),
            part_plots.contact_maps(result, out / "contact_maps.png", steps=[0, 10, 70, 130],
                                    fields=("pressure", "wear", "surface_temperature"))]
