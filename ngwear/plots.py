"""Line plots of a result along Γ_C and over time (matplotlib, no display needed).

``wear_profiles``: w(x, t_k) at a few times with the layer thickness g, the bound w ≤ g reaches
where the layer is worn through.  ``pressure_history``: p(x, t_k) and the rigid reaction λ(x, t_k)
along Γ_C, and max_x w(x, t) and max_x (u_ν − d₀)(x, t) over time.
In 3D every contact point is drawn against its x coordinate.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure


def wear_profiles(result, path, count: int = 5) -> Path:
    """w(x, t) along Γ_C at ``count`` evenly spaced steps, with g dashed; writes a PNG."""
    fig = Figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    for step, colour in _sampled(result, count):
        _along(ax, result, result.wear[step], color=colour, label=f"t = {result.times[step]:.2f}")
    ax.axhline(result.scene.contact.gap, color="black", ls="--", lw=1, label="layer thickness g")
    ax.set(xlabel="x on Γ_C", ylabel="wear w", title=f"{result.scene.name}: wear of the soft layer")
    ax.legend(fontsize=8)
    return _save(fig, path)


def pressure_history(result, path, count: int = 4) -> Path:
    """Pressure p and reaction λ along Γ_C at ``count`` steps; max w and max u_ν − d₀ over time."""
    fig = Figure(figsize=(11, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    for step, colour in _sampled(result, count):
        at = f"t = {result.times[step]:.2f}"
        _along(left, result, result.pressure[step], color=colour, label=f"p, {at}")
        _along(left, result, result.reaction[step], color=colour, ls=":", label=f"λ, {at}")
    left.set(xlabel="x on Γ_C", ylabel="contact traction", title="pressure p (solid), reaction λ (dotted)")
    left.legend(fontsize=7, ncols=2)
    t = result.times
    right.plot(t, result.wear.max(axis=1, initial=0.0), label="max wear w")
    right.plot(t, (result.normal_displacement - result.d0).max(axis=1, initial=0.0), label="max u_ν − d₀")
    right.axhline(result.scene.contact.gap, color="black", ls="--", lw=1, label="layer thickness g")
    right.set(xlabel="time t", ylabel="length", title="wear and penetration over time")
    right.legend(fontsize=8)
    return _save(fig, path)


def _sampled(result, count: int):
    """Pairs (step, colour) at ``count`` evenly spaced steps of the run, coloured by time."""
    steps = np.unique(np.linspace(0, result.steps, count).round().astype(int))
    return zip(steps, colormaps["viridis"](np.linspace(0.0, 0.9, len(steps))))


def _along(ax, result, values: np.ndarray, **kw) -> None:
    """Values at the contact points against x: a line in 2D, dots in 3D."""
    x = result.contact_points[:, 0]
    order = np.argsort(x)
    style = {} if result.scene.dim == 2 else dict(marker=".", ms=3, ls="none")
    ax.plot(x[order], values[order], **style | kw)


def _save(fig: Figure, path) -> Path:
    """Write the figure as a PNG (Agg canvas), creating the directory."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    return path
