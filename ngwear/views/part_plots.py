"""Plots a brake or pin-on-disc engineer reads off a run (matplotlib, no display needed).

``contact_maps``: the contact face Γ_C seen from above (projected on the plane ⟂ ν), coloured by the
pressure p and by the wear depth w at chosen steps (a 3D result; the colour bars name the field, the axes the
directions in the plane).
``coefficient_maps``: the contact coefficients that are fields over Γ_C (μ, κ, L: an expression, an array or a
function, not a number), one panel each: maps of the face in 3D, curves along x in 2D.
``history``: the normal force, the friction torque about the counterface's axis (the friction force ‖F_t‖
when the counterface does not turn), the worn volume and the plate's displacement over time.
``pressure_radius``: p·r against the distance r from the axis at a few steps, with its mean: under a rigid
backing plate a worn-in pad wears evenly, so p·r tends to a constant.  ``temperatures`` (``heat``): the surface
temperature along Γ_C and the body's, the face's and the counterface's temperatures over time (the contact maps add
the surface temperature's).  ``life`` (a programme): the remaining thickness over Γ_C, its tapers against the stops
and the wear per block.  Axes carry units in an SI scene.
"""
from __future__ import annotations

from pathlib import Path

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation

from ..model.coefficients import state_of
from ..results.stops import TAPERS
from ..results.units import label, unit
from .plots import _along, _sampled, _save, plain

FIELDS = {"pressure": ("pressure p", "plasma", "pressure", "pressure"),
          "wear": ("wear depth", "YlOrRd", "length", "total_wear"),
          "remaining_thickness": ("remaining thickness", "viridis", "length", "remaining_thickness"),
          "surface_temperature": ("surface temperature T", "inferno", "temperature", "surface_temperature")}
"""The fields a contact map draws: title, colour map, quantity and the result's array (pressure and wear from 0, the
temperature and the thickness from their lowest).  The wear is the total wear: w, and in ``"surface"`` runs what the
geometry updates moved into the body."""
COEFFICIENTS = {"friction_coefficient": ("friction", "friction μ", "viridis", None),
                "wear_coefficient": ("wear", "wear coefficient κ", "cividis", "wear coefficient"),
                "contact_stiffness": ("stiffness", "compliance stiffness L", "magma", "compliance stiffness")}
"""The contact coefficients of a result: its array, the scene key (``contact.<key>``), title, colour map, quantity
(its unit in an SI scene: :mod:`ngwear.results.units`; μ has none)."""


def _plane(nu: np.ndarray) -> np.ndarray:
    """Two orthonormal vectors of the plane ⟂ ν, the first along x where it can be: (x, y) for ν = ±e_z."""
    first = np.eye(3)[0] - nu[0] * nu
    if np.linalg.norm(first) < 1e-9:
        first = np.eye(3)[1] - nu[1] * nu
    first /= np.linalg.norm(first)
    second = np.cross(-nu if nu[2] <= 0 else nu, first)
    return np.array([first, second])


def _triangulation(result) -> tuple[Triangulation, sp.csr_matrix]:
    """The Γ_C facets, projected on the plane ⟂ ν, and the map from point values to their nodes' values.

    P1: the facets between the vertex points.  P2: each facet halved into four between its vertices
    and edge midpoints (values at vertices that are no contact points: :attr:`ContactPoints.at_vertices`).
    """
    disc = result.discretization
    points, mesh = disc.points, disc.mesh
    facets = [el for el in mesh.Elements(ngs.BND) if el.mat == "contact"]
    corners = np.unique([v.nr for el in facets for v in el.vertices])
    node = np.full(mesh.nv, -1)
    node[corners] = np.arange(len(corners))
    values = points.at_vertices[corners]
    triangles = [[node[v.nr] for v in el.vertices] for el in facets]
    if result.scene.mesh.order == 2:
        mid = np.full(mesh.nedge, -1)
        mid[points.edges[points.edges >= 0]] = len(corners) + np.arange((points.edges >= 0).sum())
        values = sp.vstack([values, sp.eye(points.n, format="csr")[points.edges >= 0]]).tocsr()
        triangles = []
        for el in facets:
            a, b, c = (node[v.nr] for v in el.vertices)
            at = {frozenset(v.nr for v in mesh[e].vertices): mid[e.nr] for e in el.edges}
            ab, bc, ca = (at[frozenset((el.vertices[i].nr, el.vertices[j].nr))] for i, j in ((0, 1), (1, 2), (2, 0)))
            triangles += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    xyz = np.array([mesh.vertices[int(v)].point for v in corners])
    if result.scene.mesh.order == 2:
        xyz = np.vstack([xyz, result.contact_points[points.edges >= 0]])
    xy = xyz @ _plane(np.asarray(result.scene.contact.direction)).T
    return Triangulation(xy[:, 0], xy[:, 1], np.array(triangles)), values


def _axis_name(direction: np.ndarray) -> str:
    """A direction as an axis label: ``x``, ``−z`` for a coordinate axis, else ``along (0.71, 0.71, 0)``."""
    k = int(np.argmax(np.abs(direction)))
    if abs(abs(direction[k]) - 1) < 1e-9:
        return ("" if direction[k] > 0 else "−") + "xyz"[k]
    return "along (" + ", ".join(f"{c:.2g}" for c in direction) + ")"


def _label_face(fig_axes, scene) -> None:
    """Axis labels of maps of Γ_C from above (the plane ⟂ ν), with units: under the last row, left of the first."""
    first, second = (_axis_name(v) for v in _plane(np.asarray(scene.contact.direction)))
    axes = np.atleast_2d(fig_axes)
    for ax in axes[-1]:
        ax.set_xlabel(label(scene, first, "length"), fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel(label(scene, second, "length"), fontsize=8)


def contact_maps(result, path, steps=None, fields=("pressure", "wear")) -> Path:
    """Write :func:`contact_figure` as a PNG."""
    return _save(contact_figure(result, steps, fields), path)


def contact_figure(result, steps=None, fields=("pressure", "wear")) -> Figure:
    """Γ_C from above coloured by each of ``fields`` (rows) at ``steps`` (columns; default 4 of the run)."""
    if result.scene.dim != 3:
        raise ValueError("contact maps need a 3D result (in 2D, Γ_C is a line: see plots.wear_profiles)")
    steps = [s for s, _ in _sampled(result, 4)] if steps is None else [result.step_index(s) for s in steps]
    tri, at_nodes = _triangulation(result)
    aspect = np.clip(np.ptp(tri.x) / max(np.ptp(tri.y), 1e-300), 0.35, 3.0)
    fig = Figure(figsize=((2.6 * aspect + 0.6) * len(steps) + 1, 3.0 * len(fields)), layout="constrained")
    seconds = f" {unit(result.scene, 'time')}" if result.scene.units else ""
    axes = np.atleast_2d(fig.subplots(len(fields), len(steps), squeeze=False))
    for row, name in zip(axes, fields):
        title, cmap, quantity, array = FIELDS[name]
        values = getattr(result, array)
        top = max(float(values[steps].max()), 1e-300)
        bottom = float(values[steps].min()) if name in ("surface_temperature", "remaining_thickness") else 0.0
        for ax, step in zip(row, steps):
            shaded = ax.tripcolor(tri, at_nodes @ values[step], shading="gouraud", cmap=cmap, vmin=bottom,
                                  vmax=max(top, bottom * (1 + 1e-12) + 1e-300))
            ax.set_aspect("equal")
            ax.set_title(f"t = {result.times[step]:.4g}{seconds}", fontsize=9)
            ax.tick_params(labelsize=7)
        fig.colorbar(shaded, ax=row.tolist(), shrink=0.9, format="%.3g", label=label(result.scene, title, quantity))
    _label_face(axes, result.scene)
    fig.suptitle(f"{result.scene.name}: contact face from above", fontsize=10)
    return fig


def varying(result) -> list[str]:
    """The coefficients of :data:`COEFFICIENTS` that the scene gives as fields of x (not numbers, not of the state)."""
    return [name for name, (key, *_) in COEFFICIENTS.items()
            if not isinstance(getattr(result.scene.contact, key), (int, float))
            and not state_of(getattr(result.scene.contact, key), key)]


def coefficient_figure(result, names=None) -> Figure:
    """One panel per coefficient of ``names`` (default: :func:`varying`) over Γ_C: a map in 3D, a curve in 2D.

    Each panel draws the result's array (``result.friction_coefficient``, …) at the contact points, coloured from
    its smallest to its largest value.
    """
    names = varying(result) if names is None else list(names)
    if not names:
        raise ValueError("names: no coefficient to draw (the scene's μ, κ and L are numbers)")
    dim = result.scene.dim
    tri, at_nodes = _triangulation(result) if dim == 3 else (None, None)
    aspect = np.clip(np.ptp(tri.x) / max(np.ptp(tri.y), 1e-300), 0.35, 3.0) if dim == 3 else 1.6
    fig = Figure(figsize=((2.6 * aspect + 1.2) * len(names), 3.2), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(names), squeeze=False)[0])
    for ax, name in zip(axes, names):
        key, title, cmap, quantity = COEFFICIENTS[name]
        values, named = getattr(result, name), label(result.scene, title, quantity) if quantity else title
        ax.set_title(f"{title}: contact.{key}", fontsize=9)
        ax.tick_params(labelsize=7)
        if dim == 2:
            order = np.argsort(result.contact_points[:, 0])
            ax.plot(result.contact_points[order, 0], values[order], color="C0")
            ax.set_xlabel(label(result.scene, "x on Γ_C", "length"), fontsize=8)
            ax.set_ylabel(named, fontsize=8)
            continue
        lo, hi = float(values.min()), float(values.max())   # a field that is constant after all: one colour
        shaded = ax.tripcolor(tri, at_nodes @ values, shading="gouraud", cmap=cmap, vmin=lo, vmax=hi)
        ax.set_aspect("equal")
        fig.colorbar(shaded, ax=ax, shrink=0.9, format="%.3g", label=named)
    if dim == 3:
        _label_face(axes[None], result.scene)
    fig.suptitle(f"{result.scene.name}: contact coefficients over Γ_C", fontsize=10)
    return fig


def coefficient_maps(result, path, names=None) -> Path:
    """Write :func:`coefficient_figure` as a PNG."""
    return _save(coefficient_figure(result, names), path)


def history(result, path) -> Path:
    """Normal force, friction torque (or force), worn volume and (with a plate) its displacement over time.

    A counterface that turns gets the torque about its axis; one that translates, the friction force ‖F_t‖.
    """
    scene = result.scene
    turning = result.motion.rotating
    friction = (("friction torque T (< 0: braking)", result.torque, "torque") if turning
                else ("friction force |F_t| = |Σ m μ p n*|", result.friction_force, "force"))
    panels = [("normal force Σ m (p + λ)", result.normal_force, "force"), friction,
              ("worn volume Σ m w", result.wear_volume, "volume")]
    if result.plate_displacement.shape[1]:
        panels.append(("plate displacement δ along ν", result.plate_displacement[:, 0], "length"))
    fig = Figure(figsize=(3.4 * len(panels), 3.0), layout="constrained")
    for ax, (title, values, quantity) in zip(fig.subplots(1, len(panels)), panels):
        ax.plot(result.times, values, color="C0")
        ax.set(xlabel=label(scene, "time t", "time"), title=label(scene, title, quantity))
        ax.title.set_fontsize(9)
        plain(ax, values)
    fig.suptitle(result.scene.name, fontsize=10)
    return _save(fig, path)


def life(result, path) -> Path:
    """A part's life (a programme): the remaining thickness, its tapers against the stops and the wear per block.

    The thickness over Γ_C at the last step, the columns ``taper_*`` of ``Result.stops`` and each block's mean worn
    volume per stop.
    """
    scene, stops = result.scene, result.stops
    fig = Figure(figsize=(13, 3.6), layout="constrained")
    face, taper, blocks = fig.subplots(1, 3)
    remaining = result.remaining_thickness[-1]
    if scene.dim == 3:
        tri, at_nodes = _triangulation(result)
        shaded = face.tripcolor(tri, at_nodes @ remaining, shading="gouraud", cmap="viridis")
        face.set_aspect("equal")
        fig.colorbar(shaded, ax=face, format="%.4g", label=label(scene, "remaining thickness", "length"))
        _label_face(np.array([[face]]), scene)
    else:
        _along(face, result, remaining)
        face.set(xlabel=label(scene, "x", "length"), ylabel=label(scene, "remaining thickness", "length"))
        plain(face, remaining)
    seconds = f" {unit(scene, 'time')}" if scene.units else ""
    face.set_title(f"remaining thickness at t = {result.times[-1]:.4g}{seconds}", fontsize=9)
    lengths = [c for c in TAPERS if c in stops and c != "taper_slope"]      # the slope (a ratio) without them
    for column in lengths or ["taper_slope"]:
        taper.plot(stops.index, stops[column], label=column.removeprefix("taper_").replace("_", " "))
    taper.set(xlabel="stop", ylabel=label(scene, "taper of the remaining thickness", "length") if lengths else
              "slope of the remaining thickness")
    taper.set_title("taper against stops", fontsize=9)
    taper.legend(fontsize=8)
    worn = stops.groupby("block")["worn_volume"]
    blocks.bar(worn.mean().index, worn.mean().to_numpy(), color="C1")
    blocks.set(xlabel="block", ylabel=label(scene, "worn volume per stop", "volume"))
    blocks.set_title("wear per block", fontsize=9)
    blocks.set_xticks(worn.mean().index)
    fig.suptitle(f"{scene.name}: a part's life, {len(stops)} stops", fontsize=10)
    return _save(fig, path)


def temperatures(result, path, count: int = 4) -> Path:
    """The surface temperature along Γ_C at ``count`` steps; the body's, the face's and the counterface's over time.

    The body's highest temperature, the contact face's mean and the counterface's T_f (``heat``).
    """
    scene = result.scene
    fig = Figure(figsize=(11, 4), layout="constrained")
    left, right = fig.subplots(1, 2)
    x = result.contact_points[:, 0]
    order = np.argsort(x)
    style = {} if scene.dim == 2 else dict(marker=".", ms=3, ls="none")
    for step, colour in _sampled(result, count):
        left.plot(x[order], result.surface_temperature[step][order], color=colour,
                  label=f"t = {result.times[step]:.4g}", **style)
    left.set(xlabel=label(scene, "x on Γ_C", "length"), ylabel=label(scene, "surface temperature T", "temperature"),
             title="surface temperature along Γ_C")
    left.legend(fontsize=8)
    mean = result.surface_temperature @ result.weights / result.weights.sum()
    for values, name in ((result.max_temperature, "body, highest"), (mean, "contact face, mean"),
                         (result.foundation_temperature, "counterface T_f")):
        right.plot(result.times, values, label=name)
    right.set(xlabel=label(scene, "time t", "time"), ylabel=label(scene, "temperature", "temperature"),
              title="temperatures over time")
    right.legend(fontsize=8)
    fig.suptitle(scene.name, fontsize=10)
    return _save(fig, path)


def pressure_radius(result, path, count: int = 4) -> Path:
    """p·r against r (the distance from the axis) at ``count`` steps: flat once the pad is worn in."""
    motion = result.motion
    arm = result.contact_points - motion.center
    axis = np.asarray(motion.axis, dtype=float)
    radius = np.linalg.norm(arm - np.outer(arm @ axis, axis), axis=1) if axis.ndim else np.linalg.norm(arm, axis=1)
    fig = Figure(figsize=(6.5, 4), layout="constrained")
    ax = fig.add_subplot()
    for step, colour in _sampled(result, count):
        pr = result.pressure[step] * radius
        touching = result.pressure[step] > 0
        ax.plot(radius[touching], pr[touching], ".", ms=3, color=colour, label=f"t = {result.times[step]:.4g}")
        mean = pr[touching] @ result.weights[touching] / max(result.weights[touching].sum(), 1e-300)
        ax.axhline(mean, color=colour, lw=0.8, ls="--")
    ax.set(xlabel=label(result.scene, "distance r from the axis", "length"),
           ylabel=label(result.scene, "p · r", "line load"),
           title=f"{result.scene.name}: p·r over Γ_C (dashed: its mean; worn in: constant)")
    ax.title.set_fontsize(9)
    ax.legend(fontsize=8)
    return _save(fig, path)
