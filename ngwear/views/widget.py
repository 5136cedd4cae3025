"""The explorer as ipywidgets: sliders, time slider, buttons, status, picture and plots.

The widgets are a view of an :class:`~ngwear.views.explore.Explorer`: they redraw after every
change of it, whoever made it (a slider, a button, ``explorer.set`` in a cell), and their values
are set from its state, so they always show the state that produced the picture.  A slider move
that fails shows the one-line error, puts the slider back and keeps the last good picture.
Sliders act when released (each value takes a solve and both pictures; dragging would queue them).
Every widget carries a CSS class ``ngwear-<name>`` (``ngwear-slider-<slider>`` for sliders) by
which pages and tests find it.  The widgets know the explorer by its methods only; this module
does not import :mod:`ngwear.views.explore` (which imports it for :meth:`Explorer.widget`).
"""
from __future__ import annotations

import html
import io
import itertools
import os
import threading
from pathlib import Path

import ipywidgets as W
import numpy as np
from PIL import Image

from ..model.scene import SceneError
from ..runs.simulate import RunError

LABEL = {"description_width": "100px"}



def explorer_widget(explorer, folder=None, *, confined: bool = False) -> W.VBox:
    """The widgets of ``explorer`` (an :class:`~ngwear.views.explore.Explorer`), reachable as ``explorer.controls[name]``.

    ``name`` is a slider's name, ``"time"``, ``"folder"``, ``"save_scene"``, ``"save_picture"``,
    ``"save_result"``, ``"pin"``, ``"progress"``, ``"status"``, ``"message"``, ``"picture"`` or
    ``"plots"``.  Setting a slider's ``value`` from Python acts like moving it.  The save buttons
    write numbered files into the *save into* folder, initially ``folder`` (default
    ``out/<scene name>-explore``).  ``confined`` (the app): *save into* must name ``folder`` or a
    folder inside it (relative to it, symlinks followed); the buttons refuse any other.
    """
    folder = Path(folder or Path("out") / f"{explorer.base.name}-explore").expanduser()
    view = _View(explorer, folder.resolve() if confined else folder, confined)
    explorer.controls = view.controls
    explorer.on_change(view.refresh)
    view.refresh()
    return view.box


class _View:
    def __init__(self, explorer, folder: Path, confined: bool):
        self.explorer, self.root = explorer, folder if confined else None
        self.syncing = threading.local()
        c = self.controls = {}
        for s in explorer.sliders:
            kind, fmt = (W.IntSlider, {}) if s.integer else (W.FloatSlider, {"readout_format": ".3g"})
            c[s.name] = kind(min=s.minimum, max=s.maximum, step=s.step, description=s.label,
                             continuous_update=False, style=LABEL, layout=W.Layout(width="390px"), **fmt)
            c[s.name].observe(self.on_slider, names="value")
        c["time"] = W.IntSlider(min=0, max=explorer.result.steps, description="time step", continuous_update=False,
                                style=LABEL, layout=W.Layout(width="790px"))
        c["time"].observe(self.on_time, names="value")
        c["folder"] = W.Text(value=str(folder), description="save into", style=LABEL,
                             layout=W.Layout(width="390px"))
        for name, label, act in (("save_scene", "save scene (TOML)", self.save_scene),
                                 ("save_picture", "save picture (PNG)", self.save_picture),
                                 ("save_result", "save result", self.save_result),
                                 ("pin", "pin as A (A/B)", self.toggle_pin)):
            c[name] = W.Button(description=label, layout=W.Layout(width="auto"))
            c[name].on_click(act)
        c["progress"] = W.IntProgress(value=0, min=0, max=3, description="starting", style={"description_width": "70px"},
                                      layout=W.Layout(width="240px", flex="0 0 auto"))
        c["status"] = W.HTML(layout=W.Layout(flex="1 1 auto", width="auto"))
        c["message"] = W.HTML()
        width = W.Layout(width=f"{explorer.canvas.window_size[0]}px")  # natural size, not stretched
        c["picture"], c["plots"] = W.Image(format="png", layout=width), W.Image(format="png", layout=width)
        for name, widget in c.items():
            widget.add_class(f"ngwear-slider-{name}" if name in {s.name for s in explorer.sliders} else f"ngwear-{name}")
        names = [s.name for s in explorer.sliders]
        self.box = W.VBox([
            W.HTML(f"<b>{html.escape(explorer.base.name)}</b>: sliders act when released (or step them with the "
                   "arrow keys); the time slider scrubs through the run."),
            W.GridBox([c[n] for n in names], layout=W.Layout(grid_template_columns="repeat(2, 400px)")),
            c["time"],
            W.HBox([c["save_scene"], c["save_picture"], c["save_result"], c["pin"], c["folder"]]),
            W.HBox([c["progress"], c["status"]], layout=W.Layout(width="100%")),
            c["message"], c["picture"], c["plots"]])
        self.box.add_class("ngwear-explorer")

    # ---- showing the explorer's state ----------------------------------------------------------
    def refresh(self) -> None:
        """Widgets from the explorer's state; picture, plots and status of the step on show."""
        c, ex = self.controls, self.explorer
        self._sync()
        self._progress(1, "drawing", "info")
        c["picture"].value = png_bytes(ex.picture())
        self._progress(2, "drawing", "info")
        c["plots"].value = png_bytes(ex.plots())
        c["status"].value = _text(ex.summary())
        c["pin"].description = "unpin A" if ex.pinned is not None else "pin as A (A/B)"
        c["message"].value = ""
        self._progress(3, "ready", "success")

    def _sync(self) -> None:
        """Slider values (ranges widened if needed) and time slider from the explorer, acting on nothing."""
        c, ex = self.controls, self.explorer
        self.syncing.active = True
        try:
            for name, value in ex.values.items():
                if value != value:          # NaN: a field slider whose field was replaced from Python
                    continue
                slider = c[name]
                slider.min, slider.max = min(slider.min, value), max(slider.max, value)
                slider.value = value
            c["time"].max = ex.result.steps
            c["time"].value = ex.step
        finally:
            self.syncing.active = False

    def _progress(self, value: int, description: str, style: str) -> None:
        bar = self.controls["progress"]
        bar.value, bar.description, bar.bar_style = value, description, style

    def _error(self, text: str) -> None:
        """Show a one-line error; sliders back to the state on show."""
        self._sync()
        self.controls["message"].value = _text(text, colour="#b00020")
        self._progress(3, "failed", "danger")

    # ---- acting on the explorer ------------------------------------------------------------------
    def on_slider(self, change) -> None:
        if getattr(self.syncing, "active", False):
            return
        name = next(n for n, w in self.controls.items() if w is change["owner"])
        self._progress(0, "solving", "info")
        try:
            self.explorer.set(**{name: change["new"]})
        except SceneError as err:
            self._error(f"{err} (showing the last good run)")
        except RunError as err:
            self._error(f"{name} = {change['new']:.4g}: the run stopped at {err} (showing the last good run)")
        else:
            self._progress(3, "ready", "success")

    def on_time(self, change) -> None:
        if not getattr(self.syncing, "active", False):
            self.explorer.scrub(change["new"])

    def toggle_pin(self, _button) -> None:
        (self.explorer.unpin if self.explorer.pinned is not None else self.explorer.pin)()

    def save_scene(self, _button) -> None:
        self._save(self.explorer.save_scene, ".toml", "scene")

    def save_picture(self, _button) -> None:
        self._save(self.explorer.save_picture, ".png", "picture")

    def save_result(self, _button) -> None:
        self._progress(1, "saving", "info")
        self._save(self.explorer.save_result, "", "result")
        self._progress(3, "ready", "success")

    def _save(self, save, suffix: str, what: str) -> None:
        folder = Path(self.controls["folder"].value).expanduser()
        if self.root is not None:
            folder = (self.root / folder).resolve()
            if not folder.is_relative_to(self.root):
                self._error(f"save into: {self.controls['folder'].value} is outside {self.root}, "
                            "the folder this app saves into (name it or a folder inside it)")
                return
        path = _numbered(folder, self.explorer.scene.name, suffix)
        try:
            written = save(path)
        except OSError as err:
            self._error(f"save into: cannot write {err.filename or path} ({err.strerror or err})")
            return
        except SceneError as err:                   # the folder is in use by a run
            self._error(str(err))
            return
        self.controls["message"].value = _text(f"saved {what}: {written.resolve()}")


def _numbered(folder: Path, stem: str, suffix: str) -> Path:
    """The first ``folder/stem-N{suffix}`` (N = 1, 2, …) that does not exist, not even as a broken symlink."""
    return next(p for n in itertools.count(1) if not os.path.lexists(p := folder / f"{stem}-{n}{suffix}"))


def png_bytes(image: np.ndarray) -> bytes:
    """PNG bytes of an RGB image (fast compression: the explorer redraws often)."""
    out = io.BytesIO()
    Image.fromarray(image).save(out, format="png", compress_level=1)
    return out.getvalue()


def _text(text: str, colour: str | None = None) -> str:
    """HTML of a line that wraps instead of being cut off."""
    style = "white-space: normal; line-height: 1.35; overflow-wrap: anywhere;" + (f" color: {colour};" if colour else "")
    return f'<div style="{style}">{html.escape(text)}</div>'
