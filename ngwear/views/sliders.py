"""The explorer's sliders: what each one changes in a scene, its range, and which scenes get which.

The definitions are data, in ``sliders.toml`` beside this module: a slider either sets one dotted
scene key (``key``) or scales a vector of the starting scene (``scale``: ``"load"`` scales every
traction and the body force so that the largest has the slider's magnitude, ``"speed"`` sets ‖v*‖
and keeps the foundation's direction, ``"force"`` the plate force's magnitude and ``"omega"`` the
counterface's ‖ω‖, each in its starting direction).  Ranges are absolute or relative to the starting scene's
value.  Which sliders a scene gets depends on its ``geometry.kind`` (the ``[scenes]`` table).
A new scalar parameter is a new ``[slider.NAME]`` entry with its ``key`` and a name in ``[scenes]``.
"""
from __future__ import annotations

import logging
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ..model.scene import Scene, SceneError

log = logging.getLogger(__name__)
DATA = Path(__file__).with_name("sliders.toml")


@dataclass(frozen=True)
class Slider:
    """One slider on a scene: ``name``, ``label``, absolute range and what it changes.

    Exactly one of ``key`` (a dotted scene key) and ``scale`` (``"load"`` or ``"speed"``) is set.
    """

    name: str
    label: str
    minimum: float
    maximum: float
    step: float
    key: str | None = None
    scale: str | None = None
    integer: bool = False

    def value(self, scene: Scene):
        """The slider's value in ``scene``."""
        return _read(scene, self.key, self.scale)

    def changes(self, base: Scene, value) -> dict:
        """Dotted scene changes that give the slider ``value``, relative to the starting scene ``base``."""
        if self.scale is not None:
            return SCALES[self.scale][1](base, value)
        return {self.key: value}


def sliders_for(scene: Scene) -> tuple[Slider, ...]:
    """The sliders offered for ``scene``, with absolute ranges (see the module docstring)."""
    data = _data()
    names = data["scenes"].get(scene.geometry.kind, data["scenes"]["default"])
    out = []
    for name in names:
        spec = data["slider"][name]
        lo, hi, step = spec["range"]
        if spec.get("relative", False):
            start = _read(scene, spec.get("key"), spec.get("scale"))
            if start == 0:
                log.info("explorer: no %s slider (the scene's value is 0, nothing to scale)", name)
                continue
            lo, hi, step = (_round(start * x) for x in (lo, hi, step))
        if spec.get("integer", False):
            lo, hi, step = max(1, round(lo)), round(hi), max(1, round(step))
        out.append(Slider(name, spec["label"], lo, hi, step, spec.get("key"), spec.get("scale"),
                          spec.get("integer", False)))
    return tuple(out)


@cache
def _data() -> dict:
    data = tomllib.loads(DATA.read_text(encoding="utf-8"))
    for name, spec in data["slider"].items():
        if ("key" in spec) == ("scale" in spec) or spec.get("scale", "load") not in SCALES:
            raise ValueError(f"{DATA.name}: slider.{name}: give either key or scale ({', '.join(SCALES)})")
    return data


def _read(scene: Scene, key: str | None, scale: str | None):
    """The value of a dotted scene ``key``, or of the scaled vector ``scale``."""
    if scale is not None:
        return SCALES[scale][0](scene)
    node = scene.to_dict()
    for part in key.split("."):
        node = node[part]
    return node


def _round(x: float) -> float:
    """Strip round-off from a product of decimal range ends and a starting value (0.05 · 0.1 → 0.005)."""
    return float(f"{x:.12g}")


# ---------------------------------------------------------------- scaled vectors


def load_size(scene: Scene) -> float:
    """Largest traction or body-force magnitude of a scene."""
    vectors = list(scene.loads.traction.values())
    if scene.loads.body_force is not None:
        vectors.append(scene.loads.body_force)
    return max((float(np.linalg.norm(v)) for v in vectors), default=0.0)


def scaled_load(base: Scene, size: float) -> dict:
    """Dotted load keys for the starting load pattern scaled to magnitude ``size``."""
    start = load_size(base)
    if start == 0:
        raise SceneError("load: the scene has no traction or body force to scale")
    factor = size / start
    out = {"loads.traction": {name: [factor * c for c in vec] for name, vec in base.loads.traction.items()}}
    if base.loads.body_force is not None:
        out["loads.body_force"] = [factor * c for c in base.loads.body_force]
    return out


def speed(scene: Scene) -> float:
    """‖v*‖ of the foundation."""
    return float(np.linalg.norm(scene.foundation.velocity))


def scaled_velocity(base: Scene, size: float) -> dict:
    """The dotted velocity key for the starting direction of v* at speed ``size``."""
    v = np.array(base.foundation.velocity, dtype=float)
    norm = np.linalg.norm(v)
    if norm == 0:
        raise SceneError("speed: the scene's foundation is at rest (no direction to scale)")
    return {"foundation.velocity": (size / norm * v).tolist()}


def plate_force(scene: Scene) -> float:
    """‖F‖ of the plate (0 without a plate)."""
    return float(np.linalg.norm(scene.loads.plate.force)) if scene.loads.plate is not None else 0.0


def scaled_plate_force(base: Scene, size: float) -> dict:
    """The plate force in its starting direction at magnitude ``size``."""
    return {"loads.plate.force": (size / plate_force(base) * np.asarray(base.loads.plate.force)).tolist()}


def spin(scene: Scene) -> float:
    """‖ω‖ of the counterface (0 when it does not turn)."""
    omega = scene.foundation.angular_velocity
    return float(np.linalg.norm(omega)) if omega is not None else 0.0


def scaled_spin(base: Scene, size: float) -> dict:
    """ω about the starting axis, turning the same way, at ‖ω‖ = ``size``."""
    return {"foundation.angular_velocity": (size / spin(base) * np.asarray(base.foundation.angular_velocity)).tolist()}


SCALES = {"load": (load_size, scaled_load), "speed": (speed, scaled_velocity), "force": (plate_force, scaled_plate_force),
          "omega": (spin, scaled_spin)}
