"""Line plots of a result along Γ_C and over time (matplotlib, no display needed).

``wear_profiles``: w(x, t_k) at a few times with the layer thickness g, the bound w ≤ g reaches
where the layer is worn through.  ``pressure_history``: p(x, t_k) and the rigid reaction λ(x, t_k)
along Γ_C, and max_x w(x, t) and max_x (u_ν − d₀)(x, t) over time.
In 3D every contact point is drawn against its x coordinate.  The axes of a scene in SI carry units
(:mod:`ngwear.results.units`); :func:`plain` keeps a constant curve's axis readable.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure
from matplotlib.ticker import ScalarFormatter

from ..results.folder import replacing
from ..results.units import label as unit_label


def wear_profiles(result, path, count: int = 5) -> Path:
    """The wear along Γ_C (all material removed: w, and what geometry updates moved) at ``count`` steps, g dashed."""
    fig = Figure(figsize=(7, 4), layout="constrained")
    ax = fig.add_subplot()
    for step, colour in _sampled(result, count):
        _along(ax, result, result.total_wear[step], color=colour, label=f"t = {result.times[step]:.2f}")
    ax.axhline(result.scene.contact.gap, color="black", ls="--", lw=1, label="layer thickness g")
    scene = result.scene
    ax.set(xlabel=unit_label(scene, "x on Γ_C", "length"), ylabel=unit_label(scene, "wear w", "length"),
           title=f"{scene.name}: wear of the soft layer")
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
    scene = result.scene
    left.set(xlabel=unit_label(scene, "x on Γ_C", "length"), ylabel=unit_label(scene, "contact traction", "pressure"),
             title="pressure p (solid), reaction λ (dotted)")
    left.legend(fontsize=7, ncols=2)
    t = result.times
    right.plot(t, result.max_wear, label="max wear (all removed)")
    right.plot(t, (result.normal_displacement - result.d0).max(axis=1, initial=0.0), label="max u_ν − d₀")
    right.axhline(result.scene.contact.gap, color="black", ls="--", lw=1, label="layer thickness g")
    right.set(xlabel=unit_label(scene, "time t", "time"), ylabel=unit_label(scene, "length", "length"),
              title="wear and penetration over time")
    right.legend(fontsize=8)
    return _save(fig, path)


def plain(ax, values) -> None:
    """The y axis without an offset (no ``1e-10+1e1``), powers of ten outside [1e-3, 1e4], a constant as itself.

    Values equal to round-off (a force held by a plate) get the axis ±5 % around them, not a zoom into the noise.
    """
    formatter = ScalarFormatter(useOffset=False)
    formatter.set_powerlimits((-3, 4))
    ax.yaxis.set_major_formatter(formatter)
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if len(values) and np.ptp(values) <= 1e-9 * np.abs(values).max():
        middle = float(values.mean())
        pad = 0.05 * abs(middle) or 1.0
        ax.set_ylim(middle - pad, middle + pad)


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


def _save(fig: Figure, path, dpi: int = 120) -> Path:
    """Write the figure as a PNG (Agg canvas), creating the directory; never through a link planted at its name."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with replacing(path) as tmp:
        fig.savefig(tmp, dpi=dpi)
    return path


class Panels:
    """Small matplotlib panels drawn into an RGB array and redrawn in place (no pyplot, any thread).

    Parameters
    ----------
    size : (float, float)
        Figure width and height in inches.
    dpi : int
        Pixels per inch of the image.
    """

    def __init__(self, size=(10.0, 2.6), dpi: int = 80):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.figure = Figure(figsize=size, dpi=dpi)
        self._canvas = FigureCanvasAgg(self.figure)
        self._lines, self._dim = {}, None

    def _pixels(self) -> np.ndarray:
        """The figure as it stands, RGB (height, width, 3)."""
        self._canvas.draw()
        return np.asarray(self._canvas.buffer_rgba())[..., :3].copy()


class Dashboard(Panels):
    """Three small panels at one step of a run (the explorer's plots); with heat, two more below them.

    Left: the wear w along Γ_C at the step, at the end of the run (thin grey) and g (dashed).
    Middle: the pressure p and the rigid reaction λ along Γ_C at the step.
    Right: max w and max u_ν − d₀ over the run, g dashed, the step's time as a vertical line.
    A run with a temperature (``heat.model = "conduction"``) adds a row, the figure twice as tall: the surface
    temperature T at the step along Γ_C (2D: at the end of the run thin grey) or as a map of the contact face (3D: the
    points coloured by T over the two coordinates most across ν), and the body's highest temperature and the
    counterface's over the run, the step's time as a vertical line.
    Axis ranges are fixed per result over the whole run, so that scrubbing through it compares.
    """

    _result = None
    _heated = False

    def image(self, result, step: int) -> np.ndarray:
        """RGB image (height, width, 3) of the panels for ``step`` of ``result``."""
        step = result.step_index(step)
        heated = result.scene.heat.model == "conduction"
        if (self._dim, self._heated) != (result.scene.dim, heated):
            self._build(result.scene.dim, heated)
        if self._result is not result:
            self._show_run(result)
        x = result.contact_points[self._order, 0]
        for name in ("wear", "pressure", "reaction"):
            self._lines[name].set_data(x, getattr(result, name)[step, self._order])
        self._lines["now"].set_xdata([result.times[step]] * 2)
        if heated:
            temperature = result.surface_temperature[step, self._order]
            if result.scene.dim == 2:
                self._lines["surface_temperature"].set_data(x, temperature)
            else:
                self._lines["surface_temperature"].set_array(temperature)
            self._lines["now_heat"].set_xdata([result.times[step]] * 2)
        self._lines["title"].set_text(f"t = {result.times[step]:.2f}")
        return self._pixels()

    def _build(self, dim: int, heated: bool = False) -> None:
        """Axes, labels and (empty) lines; contact points are joined in 2D and marked in 3D."""
        self.figure.clear()
        width, height = self.figure.get_size_inches() / (1, 2 if self._heated else 1)
        self.figure.set_size_inches(width, 2 * height if heated else height)
        rows = 2 if heated else 1
        self.figure.subplots_adjust(left=0.06, right=0.99, bottom=0.18 / rows, top=1 - 0.15 / rows, wspace=0.25,
                                    hspace=0.5)
        grid = self.figure.add_gridspec(rows, 6)
        wear, traction, history = (self.figure.add_subplot(grid[0, 2 * i:2 * i + 2]) for i in range(3))
        style = {} if dim == 2 else dict(marker=".", ms=3, ls="none")
        dotted = dict(ls=":") if dim == 2 else dict(style, marker="x")
        lines = {
            "end": wear.plot([], [], color="0.7", lw=1, label="end of run", **style)[0],
            "wear": wear.plot([], [], color="C3", label="w at t", **style)[0],
            "gap": wear.axhline(0, color="black", ls="--", lw=1, label="g"),
            "pressure": traction.plot([], [], color="C0", label="p", **style)[0],
            "reaction": traction.plot([], [], color="C1", label="λ", **dotted)[0],
            "max_wear": history.plot([], [], color="C3", label="max w")[0],
            "max_pen": history.plot([], [], color="C2", label="max u_ν − d₀")[0],
            "gap_t": history.axhline(0, color="black", ls="--", lw=1),
            "now": history.axvline(0, color="0.4", lw=1),
            "title": self.figure.suptitle("", x=0.5, y=0.99, fontsize=9),
        }
        wear.set(xlabel="x on Γ_C", title="wear w")
        traction.set(xlabel="x on Γ_C", title="pressure p, reaction λ")
        history.set(xlabel="time t", title="max wear and penetration")
        axes = [wear, traction, history]
        if heated:
            face, heat = self.figure.add_subplot(grid[1, :3]), self.figure.add_subplot(grid[1, 3:])
            if dim == 2:
                lines["end_temperature"] = face.plot([], [], color="0.7", lw=1, label="end of run")[0]
                lines["surface_temperature"] = face.plot([], [], color="C5", label="T at t")[0]
            else:
                lines["surface_temperature"] = face.scatter([], [], c=[], s=6, cmap="inferno")
                self.figure.colorbar(lines["surface_temperature"], ax=face).ax.tick_params(labelsize=7)
            lines.update({
                "max_temperature": heat.plot([], [], color="C3", label="body, highest")[0],
                "foundation_temperature": heat.plot([], [], color="C0", label="counterface T_f")[0],
                "now_heat": heat.axvline(0, color="0.4", lw=1),
            })
            face.set(xlabel="x on Γ_C", title="surface temperature T" + (" on Γ_C" if dim == 3 else ""))
            heat.set(xlabel="time t", title="temperatures over time")
            axes += [face, heat]
        for ax in axes:
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7, loc="upper left")
            ax.tick_params(labelsize=7)
            ax.title.set_fontsize(9)
            ax.xaxis.label.set_fontsize(8)
        self._axes, self._lines, self._dim, self._heated, self._result = axes, lines, dim, heated, None

    def _show_run(self, result) -> None:
        """Lines and axis ranges that stay while scrubbing through ``result``."""
        wear, traction, history = self._axes[:3]
        g, t = result.scene.contact.gap, result.times
        self._order = np.argsort(result.contact_points[:, 0])
        x = result.contact_points[self._order, 0]
        lines = self._lines
        lines["end"].set_data(x, result.wear[-1, self._order])
        lines["gap"].set_ydata([g, g])
        lines["gap_t"].set_ydata([g, g])
        lines["max_wear"].set_data(t, result.wear.max(axis=1, initial=0.0))
        lines["max_pen"].set_data(t, (result.normal_displacement - result.d0).max(axis=1, initial=0.0))
        span = _span(x)
        top = 1.1 * max(g, result.wear.max(initial=0.0), lines["max_pen"].get_ydata().max(initial=0.0))
        traction_top = max(result.pressure.max(initial=0.0), result.reaction.max(initial=0.0))
        times = (t[0], max(t[-1], t[0] + 1e-12))
        wear.set(xlim=span, ylim=(0, top))
        traction.set(xlim=span, ylim=(0, 1.1 * positive(traction_top)))
        history.set(xlim=times, ylim=(0, top))
        if self._heated:
            face, heat = self._axes[3:]
            lines["max_temperature"].set_data(t, result.max_temperature)
            lines["foundation_temperature"].set_data(t, result.foundation_temperature)
            low = min(result.surface_temperature.min(), result.foundation_temperature.min())
            high = max(result.max_temperature.max(), result.foundation_temperature.max())
            pad = 0.05 * (high - low) or 0.05 * abs(high) or 1.0
            heat.set(xlim=times, ylim=(low - pad, high + pad))
            if result.scene.dim == 2:
                lines["end_temperature"].set_data(x, result.surface_temperature[-1, self._order])
                face.set(xlim=span, ylim=(low - pad, high + pad))
            else:
                across = np.argsort(np.abs(result.scene.contact.direction))[:2]
                u, v = np.sort(across)
                lines["surface_temperature"].set_offsets(result.contact_points[self._order][:, [u, v]])
                lines["surface_temperature"].set_clim(result.surface_temperature.min(), high)
                face.set(xlim=_span(result.contact_points[:, u], 0.03), ylim=_span(result.contact_points[:, v], 0.03),
                         xlabel="xyz"[u], ylabel="xyz"[v])
        self._result = result


def _span(values: np.ndarray, margin: float = 0.0) -> tuple[float, float]:
    """An axis range over ``values``, widened by ``margin`` of it on each side (±1 around a single value)."""
    lo, hi = values.min(), values.max()
    return (lo - margin * (hi - lo), hi + margin * (hi - lo)) if hi > lo else (lo - 1, hi + 1)


def positive(value: float) -> float:
    """An axis end that is never zero."""
    return float(value) if value > 0 else 1.0


def convergence(studies: dict, size: str, path, columns=("V_sum", "W_sum")) -> Path:
    """Log–log plot of study errors against ``size`` ("h" or "k"), one line per study and error column.

    ``studies`` maps a label to the rows of :func:`ngwear.verify.h_study` / ``k_study``; the legend
    gives each line's observed order (least-squares slope).
    """
    fig = Figure(figsize=(6.5, 4.5))
    ax = fig.subplots()
    for label, rows in studies.items():
        sizes = np.array([r[size] for r in rows])
        for column, style in zip(columns, ("o-", "s--")):
            errs = np.array([r[column] for r in rows])
            slope = np.polyfit(np.log(sizes), np.log(errs), 1)[0]
            ax.loglog(sizes, errs, style, label=f"{label}, {column} (order {slope:.2f})")
    ax.set(xlabel=size, ylabel="error", title=f"convergence under {size}-refinement")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    return _save(fig, path)
