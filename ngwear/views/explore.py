"""Explore a scene interactively: change load, v*, κ, μ, g or the number of steps and see the new run.

:class:`Explorer` keeps the :class:`~ngwear.discrete.Discretization` of its scene and the last
:class:`~ngwear.result.Result`.  :meth:`Explorer.set` re-solves through
``simulate(scene, discretization=...)``, which keeps mesh, factorisation and contact compliance for
these parameters (only a load change costs one more back-substitution), and records what each update
took.  :meth:`Explorer.picture` and :meth:`Explorer.plots` draw the current step with a reused
:class:`~ngwear.render.Canvas` and :class:`~ngwear.plots.Dashboard`.  :meth:`Explorer.widget` puts
sliders on all of this (ipywidgets, imported only there); the logic runs and is tested without it.

The sliders' friendly names:

* ``load``: the largest traction (or body-force) magnitude; scales the starting scene's load pattern;
* ``speed``: ‖v*‖ of the foundation; the direction of the starting scene's v* is kept;
* ``wear``: κ (``contact.wear``); ``friction``: μ (``contact.friction``);
* ``gap``: g, the soft layer's thickness (``contact.gap``);
* ``steps``: the number of time steps N (``time.steps``; T is kept).

:meth:`Explorer.set` also takes any dotted scene key (``"contact.wear"``, ``"loads.traction"``, …).
"""
from __future__ import annotations

import io
import logging
import time
from dataclasses import dataclass

import numpy as np
from PIL import Image

from ..model.scene import Scene, SceneError
from ..runs.simulate import simulate
from .plots import Dashboard
from .render import Canvas

log = logging.getLogger(__name__)

DEFAULT_MAXH, DEFAULT_STEPS = 0.05, 100
"""The explorer's default resolution: the paper's (about 2 900 free DOFs, 61 contact points)."""


@dataclass(frozen=True)
class Parameter:
    """A slider: friendly ``name``, its ``label`` and range."""

    name: str
    label: str
    minimum: float
    maximum: float
    step: float


PARAMETERS = (
    Parameter("load", "load ‖f‖", 0.0, 0.3, 0.005),
    Parameter("speed", "speed ‖v*‖", 0.1, 3.0, 0.05),
    Parameter("wear", "wear κ", 0.0, 5.0, 0.05),
    Parameter("friction", "friction μ", 0.0, 2.0, 0.05),
    Parameter("gap", "layer g", 0.02, 0.5, 0.01),
    Parameter("steps", "time steps", 10, 200, 10),
)
SCENE_KEYS = {"wear": "contact.wear", "friction": "contact.friction", "gap": "contact.gap",
              "steps": "time.steps"}


@dataclass
class Update:
    """One re-solve: what changed and how long the solve and the first picture and plots took [s]."""

    changes: dict
    solve: float
    refactorised: bool
    picture: float | None = None
    plots: float | None = None

    @property
    def total(self) -> float:
        return self.solve + (self.picture or 0.0) + (self.plots or 0.0)


class Explorer:
    """A scene, its discretization, its last run and the step on show.

    Parameters
    ----------
    scene : Scene
        The starting scene; its load pattern and foundation direction are what ``load`` and
        ``speed`` scale.
    maxh, steps : float, int or None
        Resolution (``mesh.maxh``, ``time.steps``) replacing the scene's; ``None`` keeps the scene's.
        The default, the paper's resolution, updates in well under 0.5 s.
    field : {"displacement", "wear", "pressure"}
        What the picture colours (see :func:`ngwear.render.frame`).
    window_size : (int, int)
        Size of the picture in pixels.

    Attributes
    ----------
    scene, disc, result : Scene, Discretization, Result
        The current scene, its discretization and its run.
    step : int
        The step on show (initially the last).
    updates : list of Update
        Every solve so far (the first is the initial run), with its timings.
    """

    def __init__(self, scene: Scene, *, maxh: float | None = DEFAULT_MAXH, steps: int | None = DEFAULT_STEPS,
                 field: str = "displacement", window_size=(800, 330)):
        resolution = {"mesh.maxh": maxh, "time.steps": steps}
        self.base = scene.replace(**{k: v for k, v in resolution.items() if v is not None})
        self.canvas = Canvas(field, window_size=window_size)
        self.dashboard = Dashboard(size=(window_size[0] / 80, 2.6), dpi=80)
        self.updates: list[Update] = []
        self.disc = None
        self._solve(self.base, {})
        self.step = self.result.steps

    # ---- parameters -----------------------------------------------------------------------
    @property
    def values(self) -> dict:
        """Current slider values by friendly name."""
        scene = self.scene
        return {"load": _load_size(scene), "speed": float(np.linalg.norm(scene.foundation.velocity)),
                "wear": scene.contact.wear, "friction": scene.contact.friction, "gap": scene.contact.gap,
                "steps": scene.time.steps}

    def set(self, **values):
        """Change parameters (friendly names or dotted scene keys) and re-solve if anything changed.

        Returns the new :class:`~ngwear.result.Result`.  Raises :class:`~ngwear.scene.SceneError`
        (scene unchanged) for an invalid value.  The step on show keeps its time t.
        """
        dotted = {}
        for name, value in values.items():
            if name in SCENE_KEYS:
                dotted[SCENE_KEYS[name]] = value
            elif name == "load":
                dotted.update(self._load(value))
            elif name == "speed":
                dotted["foundation.velocity"] = self._velocity(value)
            elif "." in name:
                dotted[name] = value
            else:
                names = ", ".join(p.name for p in PARAMETERS)
                raise SceneError(f"{name}: not a parameter (use {names} or a dotted scene key)")
        scene = self.scene.replace(**dotted)
        if scene != self.scene:
            t = self.result.times[self.step]
            self._solve(scene, values)
            self.step = min(round(t / scene.dt), self.result.steps)
        return self.result

    def _load(self, size: float) -> dict:
        """Dotted load keys for the starting load pattern scaled to magnitude ``size``."""
        loads, base = self.base.loads, _load_size(self.base)
        if base == 0:
            raise SceneError("load: the scene has no traction or body force to scale")
        factor = size / base
        out = {"loads.traction": {name: [factor * c for c in vec] for name, vec in loads.traction.items()}}
        if loads.body_force is not None:
            out["loads.body_force"] = [factor * c for c in loads.body_force]
        return out

    def _velocity(self, speed: float) -> list:
        v = np.array(self.base.foundation.velocity, dtype=float)
        norm = np.linalg.norm(v)
        if norm == 0:
            raise SceneError("speed: the scene's foundation is at rest (no direction to scale)")
        return (speed / norm * v).tolist()

    def _solve(self, scene: Scene, changes: dict) -> None:
        operator = self.disc.__dict__.get("operator") if self.disc is not None else None
        start = time.perf_counter()
        self.result = simulate(scene, discretization=self.disc, progress=False)
        elapsed = time.perf_counter() - start
        self.scene, self.disc = scene, self.result.discretization
        refactorised = operator is None or self.disc.__dict__.get("operator") is not operator
        self.updates.append(Update(dict(changes), elapsed, refactorised))
        log.info("explorer: %s solved in %.3f s%s", changes or "scene", elapsed,
                 " (new factorisation)" if refactorised else "")

    # ---- the step on show ---------------------------------------------------------------------
    def scrub(self, step: int) -> None:
        """Show ``step`` (negative counts from the end) of the current run."""
        self.step = range(self.result.steps + 1)[step]

    def picture(self) -> np.ndarray:
        """RGB image of body, layer and foundation at the step on show."""
        return self._timed("picture", self.canvas.frame, self.result, self.step)

    def plots(self) -> np.ndarray:
        """RGB image of wear and pressure along Γ_C at the step on show and their maxima over time."""
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
        """One line on the last update: timings, reuse, and the run's key numbers and warnings."""
        u, s = self.updates[-1], self.result.summary()
        ms = lambda x: "–" if x is None else f"{1000 * x:.0f} ms"  # noqa: E731
        reuse = "new factorisation" if u.refactorised else "factorisation reused"
        text = (f"solve {ms(u.solve)} ({reuse}), picture {ms(u.picture)}, plots {ms(u.plots)} · "
                f"max wear {s['max_wear']:.4g}, max penetration {s['max_penetration']:.4g} "
                f"(g = {s['gap']:.3g})")
        notes = [] if self.result.completed else [self.result.status]
        return " · ".join([text, *notes, *self.result.warnings])

    def close(self) -> None:
        """Release the picture's plotter."""
        self.canvas.close()

    # ---- ipywidgets ---------------------------------------------------------------------------
    def widget(self):
        """The explorer as ipywidgets: parameter sliders, a time slider, progress, picture and plots.

        Sliders act when released (a solve and both pictures take ~0.2 s; dragging would queue
        them).  The controls stay reachable as ``explorer.controls[name]`` (parameter names,
        ``"time"``, ``"progress"``, ``"status"``, ``"picture"``, ``"plots"``); setting a slider's
        ``value`` from Python updates like dragging it.
        """
        import ipywidgets as W

        values = self.values
        sliders = {}
        for p in PARAMETERS:
            v = values[p.name]
            kind = W.IntSlider if p.name == "steps" else W.FloatSlider
            extra = {} if p.name == "steps" else {"readout_format": ".3g"}
            sliders[p.name] = kind(value=v, min=min(p.minimum, v), max=max(p.maximum, v), step=p.step,
                                   description=p.label, continuous_update=False,
                                   style={"description_width": "90px"}, **extra)
        controls = dict(sliders)
        controls["time"] = W.IntSlider(value=self.step, min=0, max=self.result.steps, description="time step",
                                       continuous_update=False, style={"description_width": "90px"},
                                       layout=W.Layout(width="98%"))
        controls["progress"] = W.IntProgress(value=3, min=0, max=3, description="ready",
                                             style={"description_width": "70px"})
        controls["status"] = W.Label(value=self.summary())
        controls["picture"] = W.Image(format="png")
        controls["plots"] = W.Image(format="png")
        self.controls = controls
        busy = []

        def show() -> None:
            progress = controls["progress"]
            progress.value, progress.description = 1, "drawing"
            controls["picture"].value = png_bytes(self.picture())
            progress.value = 2
            controls["plots"].value = png_bytes(self.plots())
            progress.value, progress.description = 3, "ready"
            controls["status"].value = self.summary()

        def on_parameter(change) -> None:
            name = next(k for k, s in sliders.items() if s is change["owner"])
            progress = controls["progress"]
            progress.value, progress.description, progress.bar_style = 0, "solving", "info"
            try:
                self.set(**{name: change["new"]})
            except SceneError as err:
                progress.value, progress.description, progress.bar_style = 3, "ready", "danger"
                controls["status"].value = str(err)
                return
            busy.append(True)
            controls["time"].max, controls["time"].value = self.result.steps, self.step
            busy.clear()
            progress.bar_style = "success" if self.result.completed else "warning"
            show()

        def on_time(change) -> None:
            if not busy:
                self.scrub(change["new"])
                show()

        for slider in sliders.values():
            slider.observe(on_parameter, names="value")
        controls["time"].observe(on_time, names="value")
        show()
        names = list(sliders)
        return W.VBox([
            W.HBox([W.VBox([sliders[n] for n in names[:3]]), W.VBox([sliders[n] for n in names[3:]])]),
            controls["time"], W.HBox([controls["progress"], controls["status"]]),
            controls["picture"], controls["plots"]])


def _load_size(scene: Scene) -> float:
    """Largest traction or body-force magnitude of a scene."""
    vectors = list(scene.loads.traction.values())
    if scene.loads.body_force is not None:
        vectors.append(scene.loads.body_force)
    return max((float(np.linalg.norm(v)) for v in vectors), default=0.0)


def png_bytes(image: np.ndarray) -> bytes:
    """PNG bytes of an RGB image (fast compression: the explorer redraws often)."""
    out = io.BytesIO()
    Image.fromarray(image).save(out, format="png", compress_level=1)
    return out.getvalue()
