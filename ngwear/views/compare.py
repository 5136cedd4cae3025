"""A/B comparison of two runs on the same mesh: run B (the current one) against a pinned run A.

Four panels at the time t of B's step on show, A taken at its step nearest to t: the wear w along
Γ_C (B solid, A dashed, g dashed black), the difference w_B − w_A along Γ_C, the pressure p along
Γ_C (B solid, A dashed), and max w over time (B solid, A dashed, t marked).  Axis ranges are fixed
per pair of runs, so that scrubbing through B compares.  In 3D every contact point is drawn
against its x coordinate.
"""
from __future__ import annotations

import numpy as np

from .plots import Panels, positive


def nearest_step(result, t: float) -> int:
    """The step of ``result`` whose time is nearest to ``t``."""
    return int(np.abs(result.times - t).argmin())


class Comparison(Panels):
    """The A/B panels (see the module's text), redrawn in place."""

    _pair = None

    def image(self, a, b, step: int) -> np.ndarray:
        """RGB image (height, width, 3) of the panels for ``step`` of ``b`` against ``a``."""
        if not np.array_equal(a.contact_points, b.contact_points):
            raise ValueError("A/B: the pinned run A has other contact points (another mesh); pin again")
        step = b.step_index(step)
        t = b.times[step]
        step_a = nearest_step(a, t)
        if self._dim != b.scene.dim:
            self._build(b.scene.dim)
        if self._pair is None or self._pair[0] is not a or self._pair[1] is not b:
            self._show_runs(a, b)
        x, order, lines = self._x, self._order, self._lines
        lines["wear_b"].set_data(x, b.wear[step, order])
        lines["wear_a"].set_data(x, a.wear[step_a, order])
        lines["diff"].set_data(x, b.wear[step, order] - a.wear[step_a, order])
        lines["p_b"].set_data(x, b.pressure[step, order])
        lines["p_a"].set_data(x, a.pressure[step_a, order])
        lines["now"].set_xdata([t, t])
        at_a = "" if np.isclose(a.times[step_a], t) else f", A at t = {a.times[step_a]:.2f}"
        lines["title"].set_text(f"A/B at t = {t:.2f}{at_a}: B (current) solid, A (pinned) dashed")
        return self._pixels()

    def _build(self, dim: int) -> None:
        self.figure.clear()
        self.figure.subplots_adjust(left=0.05, right=0.99, bottom=0.18, top=0.83, wspace=0.3)
        axes = self.figure.subplots(1, 4)
        wear, diff, pressure, history = axes
        style = {} if dim == 2 else dict(marker=".", ms=3, ls="none")
        lines = {
            "wear_b": wear.plot([], [], color="C3", label="w (B)", **style)[0],
            "wear_a": wear.plot([], [], color="C3", alpha=0.6, label="w (A)", **style | dict(ls="--"))[0],
            "gap": wear.axhline(0, color="black", ls="--", lw=1, label="g"),
            "diff": diff.plot([], [], color="C4", label="w_B − w_A", **style)[0],
            "zero": diff.axhline(0, color="0.6", lw=1),
            "p_b": pressure.plot([], [], color="C0", label="p (B)", **style)[0],
            "p_a": pressure.plot([], [], color="C0", alpha=0.6, label="p (A)", **style | dict(ls="--"))[0],
            "max_b": history.plot([], [], color="C3", label="max w (B)")[0],
            "max_a": history.plot([], [], color="C3", ls="--", alpha=0.6, label="max w (A)")[0],
            "now": history.axvline(0, color="0.4", lw=1),
            "title": self.figure.suptitle("", x=0.5, y=0.99, fontsize=9),
        }
        wear.set(xlabel="x on Γ_C", title="wear w")
        diff.set(xlabel="x on Γ_C", title="difference of wear")
        pressure.set(xlabel="x on Γ_C", title="pressure p")
        history.set(xlabel="time t", title="max wear over time")
        for ax in axes:
            ax.legend(fontsize=7, loc="upper left")
            ax.tick_params(labelsize=7)
            ax.title.set_fontsize(9)
            ax.xaxis.label.set_fontsize(8)
        self._axes, self._lines, self._dim, self._pair = axes, lines, dim, None

    def _show_runs(self, a, b) -> None:
        """Lines and axis ranges that stay while scrubbing through ``b``."""
        wear, diff, pressure, history = self._axes
        lines = self._lines
        self._order = np.argsort(b.contact_points[:, 0])
        self._x = x = b.contact_points[self._order, 0]
        g = b.scene.contact.gap
        lines["gap"].set_ydata([g, g])
        lines["max_b"].set_data(b.times, b.wear.max(axis=1, initial=0.0))
        lines["max_a"].set_data(a.times, a.wear.max(axis=1, initial=0.0))
        span = (x.min(), x.max()) if x.max() > x.min() else (x.min() - 1, x.max() + 1)
        top = 1.1 * max(g, a.scene.contact.gap, b.wear.max(initial=0.0), a.wear.max(initial=0.0))
        steps_a = [nearest_step(a, t) for t in b.times]
        gap = np.abs(b.wear - a.wear[steps_a]).max(initial=0.0)
        p_top = max(b.pressure.max(initial=0.0), a.pressure.max(initial=0.0))
        wear.set(xlim=span, ylim=(0, top))
        diff.set(xlim=span, ylim=(-1.1 * positive(gap), 1.1 * positive(gap)))
        pressure.set(xlim=span, ylim=(0, 1.1 * positive(p_top)))
        t_end = max(a.times[-1], b.times[-1])
        history.set(xlim=(0, t_end if t_end > 0 else 1.0), ylim=(0, top))
        self._pair = (a, b)

