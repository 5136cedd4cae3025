"""The explorer's sliders: what each one changes in a scene, its range, and which scenes get which.

The definitions are data, in ``sliders.toml`` beside this module: a slider either sets one dotted
scene key (``key``) or scales a vector of the starting scene (``scale``: ``"load"`` scales every
traction and the body force so that the largest has the slider's magnitude, ``"speed"`` sets ‖v*‖
and keeps the foundation's direction, ``"force"`` the plate force's magnitude and ``"omega"`` the
counterface's ‖ω‖, each in its starting direction).  Ranges are absolute or relative to the starting scene's
value, or to one of its :data:`MEASURES` (``relative = "shear"``: η of ``[material]``; ``"thickness"``: the
part's height above Γ_C).  Which sliders a scene gets depends on its ``geometry.kind`` (the ``[scenes]`` table)
and, for a slider of a material constant (``material.NAME``), on whether the law of its ``[material]`` takes it
(:func:`ngwear.model.materials.takes`).
A new scalar parameter is a new ``[slider.NAME]`` entry with its ``key`` and a name in ``[scenes]``.

A slider whose key is a contact coefficient that the scene gives as a field (an expression in x, y, z or a list of
values) scales the field instead of replacing it: its value is the factor s, ``contact.friction = "s * (field)"``
(a list: each value times s), its label ends in ``× field`` and its range, read as factors, is the slider's range
(relative or not: μ × [0, 2], κ × [0, 5]).  A field given as a Python function gets no slider.
"""
from __future__ import annotations

import logging
import re
import tomllib
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from ..model.function_tokens import is_token
from ..model.kinds import KINDS
from ..model.materials import takes
from ..model.scene import Scene, SceneError

log = logging.getLogger(__name__)
DATA = Path(__file__).with_name("sliders.toml")
PROGRAMMED = {"time.steps": ("programme.steps_per_stop", "steps per stop")}
"""The key and label of a slider of the time in a programme's scene, whose programme sets ``time.steps``."""
SCALED = re.compile(r"(\S+) \* \((.*)\)", re.DOTALL)
"""A field scaled by a slider, ``s * (field)``."""


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
    field: str | tuple | None = None

    def value(self, scene: Scene):
        """The slider's value in ``scene`` (the factor on the starting scene's ``field``, if it scales one)."""
        if self.field is not None:
            return field_factor(scene.value(self.key), self.field)
        return _read(scene, self.key, self.scale)

    def changes(self, base: Scene, value) -> dict:
        """Dotted scene changes that give the slider ``value``, relative to the starting scene ``base``."""
        if self.field is not None:
            return {self.key: scaled_field(self.field, value)}
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
        key = spec.get("key", "")
        if key.startswith("material.") and not takes(scene.material.kind, key.removeprefix("material.")):
            continue
        if scene.programme is not None and key in PROGRAMMED:      # the programme sets the time: its key instead
            spec = {**spec, "key": PROGRAMMED[key][0], "label": PROGRAMMED[key][1]}
        lo, hi, step = spec["range"]
        start = _read(scene, spec.get("key"), spec.get("scale"))
        if "key" in spec and isinstance(scene.value(spec["key"]), (str, tuple)):   # a field: the slider scales it
            start = scene.value(spec["key"])
            if is_token(start):
                log.info("explorer: no %s slider (%s is a Python function)", name, spec["key"])
                continue
            out.append(Slider(name, f"{spec['label']} × field", lo, hi, step, spec["key"], field=start))
            continue
        relative = spec.get("relative", False)
        if relative:
            start = MEASURES[relative](scene) if isinstance(relative, str) else start
            if start == 0:
                log.info("explorer: no %s slider (the scene's value is 0, nothing to scale)", name)
                continue
            lo, hi, step = (_round(start * x) for x in (lo, hi, step))
        if spec.get("integer", False):
            lo, hi, step = max(1, round(lo)), round(hi), max(1, round(step))
        out.append(Slider(name, spec["label"], lo, hi, step, spec.get("key"), spec.get("scale"),
                          spec.get("integer", False)))
    return tuple(out)


def field_factor(value, field) -> float:
    """The factor s with which :func:`scaled_field` of ``field`` gives ``value`` (NaN if it gives none)."""
    if value == field:
        return 1.0
    if isinstance(field, tuple):
        ratio = np.divide(value, field, out=np.full(len(field), np.nan), where=np.asarray(field) != 0)
        return float(np.nanmax(ratio)) if isinstance(value, tuple) and len(value) == len(field) else float("nan")
    match = SCALED.fullmatch(value) if isinstance(value, str) else None
    return float(match.group(1)) if match and match.group(2) == field else float("nan")


def scaled_field(field, factor: float):
    """``field`` times ``factor``: ``"s * (expression)"``, or each value of a list times s (s = 1: the field)."""
    if factor == 1:
        return field
    if isinstance(field, tuple):
        return tuple(factor * v for v in field)
    return f"{factor!r} * ({field})"


@cache
def _data() -> dict:
    data = tomllib.loads(DATA.read_text(encoding="utf-8"))
    for name, spec in data["slider"].items():
        if ("key" in spec) == ("scale" in spec) or spec.get("scale", "load") not in SCALES:
            raise ValueError(f"{DATA.name}: slider.{name}: give either key or scale ({', '.join(SCALES)})")
        if isinstance(spec.get("relative"), str) and spec["relative"] not in MEASURES:
            raise ValueError(f"{DATA.name}: slider.{name}.relative: true, false or one of {', '.join(MEASURES)}")
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


def backing(scene: Scene) -> float:
    """t_b of the scene's backing (0 without one)."""
    return float(scene.geometry.backing or 0.0)


def scaled_backing(base: Scene, size: float) -> dict:
    """A backing of thickness ``size`` (0: none), of the starting scene's backing material if it has one.

    Without a backing the scene may not name its material (``material.regions.backing`` of a missing region is
    refused): the starting scene's ``material.regions`` are kept otherwise.
    """
    regions = base.to_dict()["material"].get("regions", {})
    if size == 0:
        regions = {name: table for name, table in regions.items() if name != "backing"}
    return {"geometry.backing": float(size) if size > 0 else None, "material.regions": regions}


def shear(scene: Scene) -> float:
    """η of ``[material]`` (0 if its law takes no isotropic constants)."""
    return float(scene.material.lame[1] or 0.0) if takes(scene.material.kind, "lame_mu") else 0.0


def thickness(scene: Scene) -> float:
    """The part's height above Γ_C, ``geometry.size`` along ν (0 for a kind without one)."""
    index = KINDS[scene.geometry.kind].thickness
    return float(scene.geometry.size[index]) if index is not None and scene.geometry.size else 0.0


MEASURES = {"shear": shear, "thickness": thickness}
"""What a ``relative = "NAME"`` range is relative to."""
SCALES = {"backing": (backing, scaled_backing), "load": (load_size, scaled_load),
          "speed": (speed, scaled_velocity), "force": (plate_force, scaled_plate_force),
          "omega": (spin, scaled_spin)}
