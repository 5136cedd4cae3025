"""Study files: a base scene and the scene keys to vary, expanded into validated cases.

A study is TOML (or the same nested dict)::

    name = "friction_wear"                  # optional, default: the file's stem
    scene = "../paper_strip.toml"           # base scene, relative to the study file, or a [scene] table
    outputs = ["max_wear", "worn_volume"]   # optional, default: every output of ngwear.studies.outputs

    [set]                                   # fixed overrides of the base scene (dotted keys)
    "mesh.maxh" = 0.1

    [grid]                                  # cartesian product of the lists
    "contact.friction" = [0.2, 0.4, 0.6]
    "contact.wear" = [0.5, 1.5]

    [[cases]]                               # explicit cases, each a table of dotted keys
    "loads.traction.top" = [0.0, -0.2]

    [sample]                                # random or Latin-hypercube sample of ranges
    method = "latin_hypercube"              # or "random"
    count = 16
    seed = 1
    ranges = { "contact.gap" = [0.1, 0.3] } # [low, high]; whole numbers when both ends are

Each block gives a list of parameter sets; the study's cases are the product of the blocks given
(a grid alone is its product, cases alone are their list, a grid with cases runs every case at every
grid point).  Unquoted dotted keys (``contact.friction = [...]``) are nested tables in TOML and read the
same way.  Tables inside a case or a grid are read as dotted keys
(``"loads.traction" = {top = [0, -0.2]}`` sets ``loads.traction.top`` only).  Every case's scene is
built before anything runs: the study is refused with a
:class:`StudyError` naming the field when a field of the study is malformed, when a varied key is
accepted for none of its values (``grid.contact.frictoin: unknown key (allowed: ...)``) or when no case
is valid; a case whose value alone is invalid is kept as a ``rejected`` case with the scene's message.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..model.keys import Level
from ..model.scene import Scene, SceneError, load_scene
from .outputs import OUTPUTS

FIELDS = ("name", "scene", "outputs", "set", "grid", "cases", "sample")
SAMPLE_FIELDS = ("method", "count", "seed", "ranges")
SAMPLE_METHODS = ("latin_hypercube", "random")


class StudyError(ValueError):
    """A study field is missing, malformed or gives no valid case (the message names the field)."""


@dataclass(frozen=True)
class Case:
    """One run of a study: its parameters (dotted key → value) and its scene, or why it has none.

    ``id`` is a hash of the scene (name excluded), so a case keeps its results folder when the study
    around it changes; ``group`` is what the factorisation of the case depends on (the keys that declare
    they invalidate the mesh, the space or the stiffness): cases of one group share mesh and factorisation.
    """

    index: int
    params: dict[str, Any]
    scene: Scene | None
    error: str | None = None

    @property
    def id(self) -> str:
        data = dict(self.scene.to_dict() if self.scene else self.params, name=None)
        return hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()[:12]

    @property
    def group(self) -> str:
        """The case's mesh, space and material (the keys declared up to :attr:`Level.STIFFNESS`)."""
        return json.dumps([self.scene.signature(level) for level in Level if level <= Level.STIFFNESS])


@dataclass(frozen=True)
class Study:
    """A validated study: the base scene, its cases, the varied keys and the outputs to tabulate."""

    name: str
    base: Scene
    cases: tuple[Case, ...]
    varied: tuple[str, ...]
    grid: tuple[str, ...] = ()
    outputs: tuple[str, ...] = tuple(OUTPUTS)


def load_study(path: str | Path, overrides: dict[str, Any] | None = None) -> Study:
    """Read and validate a study TOML file; ``overrides`` are extra ``[set]`` entries (dotted keys)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as err:
        raise StudyError(f"study file: cannot read {path} ({err.strerror or err})") from None
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
        raise StudyError(f"study file: {path} is not valid TOML ({err})") from None
    return study_from_dict(data, base_dir=path.parent, name=path.stem, overrides=overrides)


def study_from_dict(data: dict, *, base_dir: str | Path = ".", name: str = "study",
                    overrides: dict[str, Any] | None = None) -> Study:
    """Validate a nested dict (as read from TOML) into a :class:`Study`; scene paths are relative to ``base_dir``."""
    if not isinstance(data, dict):
        raise StudyError("study: must be a table")
    for key in data:
        if key not in FIELDS:
            raise StudyError(f"{key}: unknown study field (allowed: {', '.join(FIELDS)})")
    name = data.get("name", name)
    if not isinstance(name, str) or not name:
        raise StudyError(f"name: must be a non-empty string (got {name!r})")
    base = _base(data.get("scene"), Path(base_dir))
    fixed = {**_flat(_table(data, "set"), "set"), **(overrides or {})}
    try:
        base = base.replace(**fixed)
    except SceneError as err:
        raise StudyError(f"set.{err}") from None
    blocks = _blocks(data)
    if not blocks:
        raise StudyError("grid: nothing to vary (give a [grid], [[cases]] or [sample])")
    owner = {key: where for where, sets in blocks for params in sets for key in params}
    for where, sets in blocks:
        for key in {k for params in sets for k in params}:
            if owner[key] != where:
                raise StudyError(f"{where}.{key}: also varied by {owner[key]}")
    cases = tuple(_case(i, {k: v for p in combo for k, v in p.items()}, base, owner)
                  for i, combo in enumerate(itertools.product(*(sets for _, sets in blocks))))
    _refuse_invalid(cases, owner)
    grid = tuple(k for k, where in owner.items() if where == "grid")
    return Study(name, base, cases, tuple(owner), grid, _outputs(data.get("outputs")))


# ---------------------------------------------------------------- blocks


def _blocks(data: dict) -> list[tuple[str, list[dict]]]:
    """(where, list of parameter sets) for each block given, in the order grid, cases, sample."""
    blocks = []
    if "grid" in data:
        grid = _flat(_table(data, "grid"), "grid")
        for key, values in grid.items():
            if not isinstance(values, list) or not values:
                raise StudyError(f"grid.{key}: must be a non-empty list of values (got {values!r})")
        blocks.append(("grid", [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())]))
    if "cases" in data:
        cases = data["cases"]
        if not isinstance(cases, list) or not cases or not all(isinstance(c, dict) for c in cases):
            raise StudyError(f"cases: must be a non-empty list of tables ([[cases]]) (got {cases!r})")
        blocks.append(("cases", [_flat(c, f"cases[{i}]") for i, c in enumerate(cases)]))
    if "sample" in data:
        blocks.append(("sample.ranges", _sample(_table(data, "sample"))))
    for where, sets in blocks:
        if not all(sets):
            raise StudyError(f"{where}: names no scene key")
    return blocks


def _sample(spec: dict) -> list[dict]:
    """Parameter sets of a Latin-hypercube (scipy.stats.qmc) or uniformly random sample of the ranges."""
    for key in spec:
        if key not in SAMPLE_FIELDS:
            raise StudyError(f"sample.{key}: unknown field (allowed: {', '.join(SAMPLE_FIELDS)})")
    method = spec.get("method", "latin_hypercube")
    if method not in SAMPLE_METHODS:
        raise StudyError(f"sample.method: must be one of {', '.join(SAMPLE_METHODS)} (got {method!r})")
    count, seed = spec.get("count"), spec.get("seed", 0)
    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise StudyError(f"sample.count: must be a whole number >= 1 (got {count!r})")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise StudyError(f"sample.seed: must be a whole number >= 0 (got {seed!r})")
    ranges = _flat(_table(spec, "ranges", "sample"), "sample.ranges")
    for key, bounds in ranges.items():
        ok = (isinstance(bounds, list) and len(bounds) == 2
              and all(isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b) for b in bounds))
        if not ok or bounds[0] >= bounds[1]:
            raise StudyError(f"sample.ranges.{key}: must be [low, high] with low < high (got {bounds!r})")
    from scipy.stats import qmc  # scipy.stats takes 0.7 s to import: only when sampling

    rng = np.random.default_rng(seed)
    unit = (qmc.LatinHypercube(d=len(ranges), rng=rng).random(count) if method == "latin_hypercube"
            else rng.random((count, len(ranges))))
    sets = [{} for _ in range(count)]
    for column, (key, (lo, hi)) in enumerate(ranges.items()):
        whole = isinstance(lo, int) and isinstance(hi, int)
        for params, u in zip(sets, unit[:, column]):
            params[key] = min(int(lo + u * (hi - lo + 1)), hi) if whole else float(lo + u * (hi - lo))
    return sets


# ---------------------------------------------------------------- cases


def _case(index: int, params: dict, base: Scene, owner: dict) -> Case:
    try:
        return Case(index, params, base.replace(**params))
    except SceneError as err:
        return Case(index, params, None, str(err))


def _refuse_invalid(cases: tuple[Case, ...], owner: dict) -> None:
    """Refuse the study if a varied key is accepted for none of its values, or if no case is valid."""
    for key, where in owner.items():
        errors = [c.error for c in cases if c.error and _names(c.error, key)]
        if len(errors) == len(cases):
            field_name = errors[0].split(":", 1)[0]
            text = errors[0] if field_name == key else f"{key}: {errors[0]}"
            raise StudyError(f"{where}.{text}")
    if all(c.error for c in cases):
        first = cases[0]
        raise StudyError(f"{_where(first, owner)}: no valid case; case 0: {first.error}")


def _names(error: str, key: str) -> bool:
    """Whether a scene error names ``key`` or a table on its path (e.g. ``contact`` for ``contact.friction``)."""
    field_name = error.split(":", 1)[0]
    return key == field_name or key.startswith(field_name + ".")


def _where(case: Case, owner: dict) -> str:
    return "/".join(dict.fromkeys(owner[k] for k in case.params))


# ---------------------------------------------------------------- fields


def _base(spec: Any, base_dir: Path) -> Scene:
    if isinstance(spec, str):
        try:
            return load_scene(base_dir / spec)
        except SceneError as err:
            raise StudyError(f"scene: {err}") from None
    if isinstance(spec, dict):
        try:
            return Scene.from_dict(spec)
        except SceneError as err:
            raise StudyError(f"scene.{err}") from None
    raise StudyError(f"scene: must be a scene file path or a [scene] table (got {spec!r})")


def _table(data: dict, key: str, prefix: str = "") -> dict:
    value = data.get(key, {})
    if not isinstance(value, dict):
        name = f"{prefix}.{key}" if prefix else key
        raise StudyError(f"{name}: must be a table of dotted scene keys (got {value!r})")
    return value


def _flat(table: dict, where: str) -> dict[str, Any]:
    """``{"contact": {"friction": x}}`` and ``{"contact.friction": x}`` → ``{"contact.friction": x}``."""
    out = {}
    for key, value in table.items():
        if isinstance(value, dict):
            for sub, leaf in _flat(value, f"{where}.{key}").items():
                out[f"{key}.{sub}"] = leaf
        else:
            out[key] = value
    return out


def _outputs(names: Any) -> tuple[str, ...]:
    if names is None:
        return tuple(OUTPUTS)
    if not isinstance(names, list) or not names:
        raise StudyError(f"outputs: must be a non-empty list of output names (got {names!r})")
    for name in names:
        if name not in OUTPUTS:
            raise StudyError(f"outputs: unknown output {name!r} (allowed: {', '.join(OUTPUTS)})")
    return tuple(dict.fromkeys(names))
