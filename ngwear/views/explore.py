"""Explore a scene interactively: move its sliders and see the new run.

:class:`Explorer` keeps the :class:`~ngwear.numerics.discrete.Discretization` of its scene and the
last good :class:`~ngwear.results.result.Result`.  :meth:`Explorer.set` re-solves through
``simulate(scene, discretization=...)``, which keeps mesh, factorisation and contact compliance for
the sliders' parameters, and records what each update took.  A change that fails, an invalid value
(:class:`~ngwear.model.scene.SceneError`) or a run that stops part-way (:class:`RunError`), leaves
the explorer as it was: scene, result and pictures stay those of the last good run.

The sliders a scene gets, their ranges and what they change are data (:mod:`ngwear.views.sliders`);
for the paper's scene they are ``load`` (the largest traction, scaling the load pattern), ``speed``
(‖v*‖, direction kept), ``wear`` κ, ``friction`` μ, ``gap`` g and ``steps`` N.
:meth:`Explorer.set` also takes any dotted scene key (``"contact.wear"``, ``"loads.traction"``, …).

:meth:`Explorer.picture` and :meth:`Explorer.plots` draw the step on show with a reused
:class:`~ngwear.views.render.Canvas` and :class:`~ngwear.views.plots.Dashboard`; after
:meth:`Explorer.pin` the plots compare the current run with the pinned one
(:class:`~ngwear.views.compare.Comparison`).  ``save_scene``, ``save_picture`` and ``save_result``
keep what is shown: a TOML scene that ``ngwear run`` reproduces, the PNG, and the folder
``ngwear run`` writes.  Views register with :meth:`Explorer.on_change` and are told after every
change, whoever made it, so they always show the state that produced the picture
(:meth:`Explorer.widget`, ipywidgets, imported only there).  Every method may be called from any
thread (JupyterLab runs widget callbacks on a subshell thread); one lock orders them.
"""
from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import tomli_w
from PIL import Image

from ..model.keys import Level
from ..model.scene import Scene, SceneError
from ..numerics.discrete import Reuse
from ..results.folder import replacing
from ..runs.simulate import RunError, simulate
from .compare import Comparison, nearest_step
from .plots import Dashboard
from .render import Canvas
from .sliders import sliders_for

log = logging.getLogger(__name__)


@dataclass
class Update:
    """One re-solve: what changed and how long the solve and the first picture and plots took [s]."""

    changes: dict
    solve: float
    reuse: Reuse
    picture: float | None = None
    plots: float | None = None

    @property
    def refactorised(self) -> bool:
        """Whether the solve needed a new factorisation of the stiffness."""
        return self.reuse.rebuilt <= Level.STIFFNESS

    @property
    def total(self) -> float:
        return self.solve + (self.picture or 0.0) + (self.plots or 0.0)


class Explorer:
    """A scene, its discretization, its last good run and the step on show.

    Parameters
    ----------
    scene : Scene
        The starting scene; its load pattern and foundation direction are what ``load`` and
        ``speed`` scale, and relative slider ranges are relative to its values.
    maxh, steps : float, int or None
        Resolution (``mesh.maxh``, ``time.steps``) replacing the scene's; ``None`` keeps the scene's.
    field : {"displacement", "wear", "pressure"}
        What the picture colours (see :func:`ngwear.views.render.frame`).
    window_size : (int, int)
        Size of the picture in pixels.

    Attributes
    ----------
    scene, disc, result : Scene, Discretization, Result
        The current scene, its discretization and its run.
    sliders : tuple of Slider
        The scene's sliders (:func:`ngwear.views.sliders.sliders_for`).
    step : int
        The step on show (initially the last).
    pinned : Result or None
        Run A of the A/B comparison.
    updates : list of Update
        Every solve so far (the first is the initial run), with its timings.

    Raises
    ------
    RunError
        If the starting scene's run stops part-way.
    """

    def __init__(self, scene: Scene, *, maxh: float | None = None, steps: int | None = None,
                 field: str = "displacement", window_size=(800, 330)):
        resolution = {"mesh.maxh": maxh, "time.steps": steps}
        self.base = scene.replace(**{k: v for k, v in resolution.items() if v is not None})
        self.sliders = sliders_for(self.base)
        self.canvas = Canvas(field, window_size=window_size)
        size = (window_size[0] / 80, 2.6)
        self.dashboard, self.comparison = Dashboard(size=size, dpi=80), Comparison(size=size, dpi=80)
        self.updates: list[Update] = []
        self.disc, self.pinned, self._views = None, None, []
        self._lock = threading.RLock()
        self._solve(self.base, {})
        self.step = self.result.steps

    # ---- parameters -----------------------------------------------------------------------
    @property
    def values(self) -> dict:
        """Current slider values by name."""
        return {s.name: s.value(self.scene) for s in self.sliders}

    def set(self, **values):
        """Change parameters (slider names or dotted scene keys) and re-solve if anything changed.

        Returns the new :class:`~ngwear.results.result.Result`.  The step on show keeps its time t.

        Raises
        ------
        SceneError
            For an unknown name or an invalid value.
        RunError
            If the new run stops part-way.  Either way the explorer keeps its last good run.
        """
        with self._lock:
            sliders = {s.name: s for s in self.sliders}
            dotted = {}
            for name, value in values.items():
                if name in sliders:
                    dotted.update(sliders[name].changes(self.base, value))
                elif "." in name:
                    dotted[name] = value
                else:
                    raise SceneError(f"{name}: not a parameter (use {', '.join(sliders)} or a dotted scene key)")
            scene = self.scene.replace(**dotted)
            if scene != self.scene:
                t = self.result.times[self.step]
                self._solve(scene, values)
                self.step = nearest_step(self.result, t)
                if self.pinned is not None and not np.array_equal(self.pinned.contact_points,
                                                                  self.result.contact_points):
                    log.info("explorer: unpinned run A (the mesh changed)")
                    self.pinned = None
                self._changed()
            return self.result

    def _solve(self, scene: Scene, changes: dict) -> None:
        reuse = self.disc.reuse(scene) if self.disc is not None else Reuse(Level.MESH)
        start = time.perf_counter()
        result = simulate(scene, discretization=self.disc, progress=False)
        elapsed = time.perf_counter() - start
        if not result.completed:
            raise RunError(result.status, result)
        self.scene, self.result, self.disc = scene, result, result.discretization
        self.updates.append(Update(dict(changes), elapsed, reuse))
        log.info("explorer: %s solved in %.3f s (%s)", changes or "scene", elapsed, reuse)

    # ---- the step on show, A/B --------------------------------------------------------------
    def scrub(self, step: int) -> None:
        """Show ``step`` (negative counts from the end) of the current run."""
        with self._lock:
            step = self.result.step_index(step)
            if step != self.step:
                self.step = step
                self._changed()

    def pin(self) -> None:
        """Keep the current run as A: the plots then compare every later run (B) with it."""
        with self._lock:
            self.pinned = self.result
            self._changed()

    def unpin(self) -> None:
        """Drop run A; the plots show the current run alone."""
        with self._lock:
            self.pinned = None
            self._changed()

    # ---- pictures -------------------------------------------------------------------------
    def picture(self) -> np.ndarray:
        """RGB image of body, layer and foundation at the step on show."""
        with self._lock:
            return self._timed("picture", self.canvas.frame, self.result, self.step)

    def plots(self) -> np.ndarray:
        """RGB image of wear and pressure along Γ_C at the step on show and of the maxima over time.

        With heat, a row of temperatures below (:class:`~ngwear.views.plots.Dashboard`).  With a pinned run A, the
        A/B panels (current run B against A, and the difference of wear).
        """
        with self._lock:
            if self.pinned is not None:
                return self._timed("plots", self.comparison.image, self.pinned, self.result, self.step)
            return self._timed("plots", self.dashboard.image, self.result, self.step)

    def _timed(self, kind: str, draw, *args) -> np.ndarray:
        """Draw, and record the time in the last update if this is its first drawing of that kind."""
        start = time.perf_counter()
        image = draw(*args)
        last = self.updates[-1]
        if getattr(last, kind) is None:
            setattr(last, kind, time.perf_counter() - start)
        return image

    def summary(self) -> str:
        """One line on the last update: timings, reuse, the run's key numbers and warnings, and A/B."""
        with self._lock:
            u, s = self.updates[-1], self.result.summary()
            ms = lambda x: "–" if x is None else f"{1000 * x:.0f} ms"  # noqa: E731
            reuse = u.reuse
            extremes = (f"max wear {s['max_wear']:.4g}, max penetration {s['max_penetration']:.4g} "
                        f"(g = {s['gap']:.3g})" if "max_wear" in s else "no step computed")
            parts = [f"solve {ms(u.solve)} ({reuse}), picture {ms(u.picture)}, plots {ms(u.plots)}", extremes,
                     *_temperatures(s), *self.result.warnings]
            if self.pinned is not None:
                parts.append(self._ab_line())
            return " · ".join(parts)

    def _ab_line(self) -> str:
        a, b = self.pinned, self.result
        was = {s.name: s.value(a.scene) for s in self.sliders}
        changed = [f"{name} {_short(was[name])} → {_short(now)}" for name, now in self.values.items()
                   if not np.isclose(now, was[name])]
        wear_a = a.wear[nearest_step(a, b.times[self.step])]
        difference = np.abs(b.wear[self.step] - wear_a).max(initial=0.0)
        return (f"A/B: B differs from A in {', '.join(changed)}" if changed else "A/B: B has A's parameters") + \
            f"; max |w_B − w_A| at t = {b.times[self.step]:.2f}: {difference:.4g}"

    # ---- keeping what is shown ----------------------------------------------------------------
    def save_scene(self, path) -> Path:
        """Write the current scene as TOML; ``ngwear run`` on it reproduces the current run."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with self._lock:
            text = tomli_w.dumps(self.scene.to_dict())
        with replacing(path) as tmp:                # never through a link planted at the name
            tmp.write_text(f"# saved by the ngwear explorer\n{text}", encoding="utf-8")
        return path

    def save_picture(self, path) -> Path:
        """Write the picture on show as a PNG."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        with replacing(path) as tmp:
            Image.fromarray(self.picture()).save(tmp)
        return path

    def save_result(self, directory) -> Path:
        """Write the current run as ``ngwear run`` does: results, checkpoint, VTU/PVD and the pictures."""
        from ..results.checkpoint import write_checkpoint
        from ..results.folder import clear, hold
        from .pictures import write_pictures
        with self._lock:
            result = self.result
        with hold(directory, "save into"):          # a FolderError while another run writes there
            clear(directory)                        # an earlier run's files go: the folder holds this run alone
            out = result.save(directory)
            write_checkpoint(out, result)
            write_pictures(result, out)
        return out

    # ---- views ------------------------------------------------------------------------------
    def on_change(self, callback) -> None:
        """Call ``callback()`` after every change of scene, run, step on show or pin."""
        self._views.append(callback)

    def _changed(self) -> None:
        for callback in self._views:
            callback()

    def close(self) -> None:
        """Release the picture's plotter."""
        self.canvas.close()

    def widget(self, folder=None, *, confined: bool = False):
        """The explorer as ipywidgets, saving into ``folder`` (see :func:`ngwear.views.widget.explorer_widget`)."""
        from .widget import explorer_widget
        return explorer_widget(self, folder, confined=confined)


def _temperatures(summary: dict) -> list[str]:
    """The run's highest temperatures and when (a run with ``heat``), for the summary line."""
    if "max_temperature" not in summary:
        return []
    return [f"max T {summary['max_temperature']:.4g} at t = {summary['max_temperature_time']:.4g}, counterface "
            f"{summary['max_foundation_temperature']:.4g}"]


def _short(value) -> str:
    return f"{value:.3g}" if isinstance(value, float) else str(value)

