"""Study files: a base scene and the scene keys to vary, expanded into validated cases.

A study is TOML (or the same nested dict)::

    name = "friction_wear"                  # optional, default: the file's stem; a plain name, as a scene's
    max_cases = 100000                      # optional: a larger study is refused before it is built
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
grid point): n = Π_grid |values| · |cases| · count, refused above ``max_cases`` before anything is built.
Unquoted dotted keys (``contact.friction = [...]``) are nested tables in TOML and read the same way.
Tables inside a case or a grid are read as dotted keys (``"loads.traction" = {top = [0, -0.2]}`` sets
``loads.traction.top`` only).  Every case's scene is built before anything runs: the study is refused
with a :class:`StudyError` naming the field when a field of the study is malformed, when a varied key is
accepted for none of its values (``grid.contact.frictoin: unknown key (allowed: ...)``) or when no case
is valid; a case whose value alone is invalid is kept as a ``rejected`` case with the scene's message.

Each case runs once, so a study that would run one scene twice is refused naming where: a scene key
given twice (``"contact.friction"`` beside ``[grid.contact] friction``, ``[set]`` beside ``[grid]``,
a key inside another: ``loads.traction`` beside ``loads.traction.top``), a value listed twice, two equal
``[[cases]]`` or sample draws, and two cases whose scenes are equal once validated (``1`` and ``1.0``).
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
from .tables import StudyError, as_text, first_repeat, flat, shown, table_of, whole_number

FIELDS = ("name", "scene", "outputs", "max_cases", "set", "grid", "cases", "sample")
SAMPLE_FIELDS = ("method", "count", "seed", "ranges")
SAMPLE_METHODS = ("latin_hypercube", "random")
MAX_CASES = 100_000
"""Default of a study's ``max_cases``: a larger study is refused before its cases are built."""


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
    """A validated study: the base scene, its cases, the varied keys and the outputs to tabulate.

    Build with :func:`load_study`.

    Attributes
    ----------
    name : str
        The study's name (its file's stem): the output folder ``out/<name>``.
    base : Scene
        The scene every case starts from (with the study's ``[set]``).
    cases : tuple of Case
        Each case's index, its values of the varied keys, its scene (None and an ``error`` when invalid).
    varied : tuple of str
        The dotted scene keys the cases vary.
    grid : tuple of str
        The keys of ``[grid]`` (every combination); the others come from ``[cases]``.
    outputs : tuple of str
        The numbers each case's row gets (:data:`ngwear.studies.outputs.OUTPUTS`).
    """

    name: str
    base: Scene
    cases: tuple[Case, ...]
    varied: tuple[str, ...]
    grid: tuple[str, ...] = ()
    outputs: tuple[str, ...] = tuple(OUTPUTS)


def load_study(path: str | Path, overrides: dict[str, Any] | None = None) -> Study:
    """Read and validate a study TOML file.

    Parameters
    ----------
    path : str or Path
        The study file; its ``scene`` is relative to it.
    overrides : dict, optional
        Extra ``[set]`` entries (dotted scene keys), e.g. ``{"time.steps": 10}``.

    Returns
    -------
    Study
        The study with every case's scene validated (an invalid case keeps its error and is not run).

    Raises
    ------
    StudyError
        The file is missing or not TOML, a field is unknown or malformed, or no case is valid (one line naming
        the field).
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as err:
        raise StudyError(f"study file: cannot read {path} ({err.strerror or err})") from None
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
        raise StudyError(f"study file: {path} is not valid TOML ({err})") from None
    except RecursionError:
        raise StudyError(f"study file: {path} is nested too deeply to read") from None
    return study_from_dict(data, base_dir=path.parent, name=path.stem, overrides=overrides)


def study_from_dict(data: dict, *, base_dir: str | Path = ".", name: str = "study",
                    overrides: dict[str, Any] | None = None) -> Study:
    """Validate a nested dict (as read from TOML) into a :class:`Study`; scene paths are relative to ``base_dir``."""
    if not isinstance(data, dict):
        raise StudyError("study: must be a table")
    for key in data:
        if key not in FIELDS:
            raise StudyError(f"{key}: unknown study field (allowed: {', '.join(FIELDS)})")
    name = _name(data.get("name", name))
    limit = whole_number(data.get("max_cases", MAX_CASES), "max_cases", 1)
    base = _base(data.get("scene"), Path(base_dir))
    fixed = flat(table_of(data, "set"), "set")
    pending, refusal = {}, None
    try:
        base = base.replace(**{**fixed, **(overrides or {})})
    except SceneError as err:       # it may need the varied keys (material.regions.backing: a geometry.backing)
        pending, refusal = {**fixed, **(overrides or {})}, f"set.{err}"
    blocks = []                            # (where, its keys, its sizes, its parameter sets when built)
    if "grid" in data:
        grid = _grid(data)
        blocks.append(("grid", list(grid), [len(v) for v in grid.values()],
                       lambda: [dict(zip(grid, combo)) for combo in itertools.product(*grid.values())]))
    if "cases" in data:
        listed = _listed(data)
        blocks.append(("cases", list(dict.fromkeys(k for c in listed for k in c)), [len(listed)], lambda: listed))
    if "sample" in data:
        sample = _sample(table_of(data, "sample"))
        blocks.append(("sample.ranges", list(sample[3]), [sample[1]], lambda: _draw(*sample)))
    if not blocks:
        raise StudyError("grid: nothing to vary (give a [grid], [[cases]] or [sample])")
    _refuse_large({where.split(".")[0]: sizes for where, _, sizes, _ in blocks}, limit)
    owner = {k: where for where, keys, _, _ in blocks for k in keys}
    _refuse_conflicts([*(("set", k) for k in fixed), *((where, k) for where, keys, _, _ in blocks for k in keys),
                       *(("--set", k) for k in overrides or ())])
    cases = tuple(_case(i, {k: v for p in combo for k, v in p.items()}, base, pending)
                  for i, combo in enumerate(itertools.product(*(build() for *_, build in blocks))))
    if refusal and all(c.error for c in cases):
        raise StudyError(refusal)
    _refuse_invalid(cases, owner)
    _refuse_same_scenes(cases, owner)
    grid_keys = tuple(k for k, where in owner.items() if where == "grid")
    return Study(name, base, cases, tuple(owner), grid_keys, _outputs(data.get("outputs")))


# ---------------------------------------------------------------- blocks


def _grid(data: dict) -> dict[str, list]:
    """The grid's lists by dotted key, each non-empty and without a value listed twice."""
    grid = flat(table_of(data, "grid"), "grid")
    if not grid:
        raise StudyError("grid: names no scene key")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise StudyError(f"grid.{key}: must be a non-empty list of values (got {values!r})")
        if repeat := first_repeat(values):
            raise StudyError(f"grid.{key}: {as_text(values[repeat[0]])} is listed twice (give each value once)")
    return grid


def _listed(data: dict) -> list[dict]:
    """The ``[[cases]]`` as dotted keys, each naming a key and none given twice."""
    cases = data["cases"]
    if not isinstance(cases, list) or not cases or not all(isinstance(c, dict) for c in cases):
        raise StudyError(f"cases: must be a non-empty list of tables ([[cases]]) (got {cases!r})")
    cases = [flat(c, f"cases[{i}]") for i, c in enumerate(cases)]
    for i, params in enumerate(cases):
        if not params:
            raise StudyError(f"cases[{i}]: names no scene key")
        _refuse_conflicts([(f"cases[{i}]", k) for k in params])
    if repeat := first_repeat(cases):
        raise StudyError(f"cases[{repeat[1]}]: same as cases[{repeat[0]}] (give each case once)")
    return cases


def _sample(spec: dict) -> tuple[str, int, int, dict[str, list]]:
    """The sample's method, count, seed and ranges, validated (nothing drawn yet)."""
    for key in spec:
        if key not in SAMPLE_FIELDS:
            raise StudyError(f"sample.{key}: unknown field (allowed: {', '.join(SAMPLE_FIELDS)})")
    method = spec.get("method", "latin_hypercube")
    if method not in SAMPLE_METHODS:
        raise StudyError(f"sample.method: must be one of {', '.join(SAMPLE_METHODS)} (got {method!r})")
    count, seed = whole_number(spec.get("count"), "sample.count", 1), whole_number(spec.get("seed", 0), "sample.seed", 0)
    ranges = flat(table_of(spec, "ranges", "sample"), "sample.ranges")
    if not ranges:
        raise StudyError("sample.ranges: names no scene key")
    for key, bounds in ranges.items():
        ok = (isinstance(bounds, list) and len(bounds) == 2
              and all(isinstance(b, (int, float)) and not isinstance(b, bool) and math.isfinite(b) for b in bounds))
        if not ok or bounds[0] >= bounds[1]:
            raise StudyError(f"sample.ranges.{key}: must be [low, high] with low < high (got {bounds!r})")
    return method, count, seed, ranges


def _draw(method: str, count: int, seed: int, ranges: dict[str, list]) -> list[dict]:
    """Parameter sets of a Latin-hypercube (scipy.stats.qmc) or uniformly random sample of the ranges."""
    from scipy.stats import qmc  # scipy.stats is slow to import: only when sampling

    rng = np.random.default_rng(seed)
    unit = (qmc.LatinHypercube(d=len(ranges), rng=rng).random(count) if method == "latin_hypercube"
            else rng.random((count, len(ranges))))
    sets = [{} for _ in range(count)]
    for column, (key, (lo, hi)) in enumerate(ranges.items()):
        whole = isinstance(lo, int) and isinstance(hi, int)
        for params, u in zip(sets, unit[:, column]):
            params[key] = min(int(lo + u * (hi - lo + 1)), hi) if whole else float(lo + u * (hi - lo))
    if repeat := first_repeat(sets):
        raise StudyError(f"sample.ranges: draws {repeat[0]} and {repeat[1]} are the same ({shown(sets[repeat[0]])}): "
                         "whole-number ranges repeat values (draw fewer, or vary them in a [grid])")
    return sets


def _refuse_large(factors: dict[str, list[int]], limit: int) -> None:
    """Refuse a study of more than ``limit`` cases, counted from the blocks' sizes before any case is built."""
    sizes = [n for block in factors.values() for n in block]
    count = math.prod(sizes)
    if count > limit:
        product = f"{' × '.join(map(str, sizes))} = " if len(sizes) > 1 else ""
        raise StudyError(f"{'/'.join(factors)}: {product}{count} cases, more than max_cases = {limit} "
                         f"(give max_cases = {count} in the study to run them all)")


def _refuse_conflicts(given: list[tuple[str, str]]) -> None:
    """Refuse a scene key given twice, or inside another one given, by blocks applied to one scene.

    ``given``: (where, dotted key) in the order set, grid, cases, sample.ranges, --set, the keys of the
    cases once each (different cases vary the same keys); ``--set`` overrides ``[set]``.
    """
    exact: dict[str, list] = {}
    inside: dict[str, list] = {}                   # a proper prefix of a key given → who gave that key
    for where, key in given:
        prefixes = [key.rsplit(".", n)[0] for n in range(1, key.count(".") + 1)]
        earlier = [*exact.get(key, ()), *inside.get(key, ()), *(e for p in prefixes for e in exact.get(p, ()))]
        for w, k in earlier:
            if (w, where) != ("set", "--set") and not w == where == "cases":
                label = f"--set {key}" if where == "--set" else where if key == k else f"{where}.{key}"
                raise StudyError(f"{w}.{k}: also {'fixed' if where in ('set', '--set') else 'varied'} by {label}")
        exact.setdefault(key, []).append((where, key))
        for p in prefixes:
            inside.setdefault(p, []).append((where, key))


# ---------------------------------------------------------------- cases


def _case(index: int, params: dict, base: Scene, fixed: dict) -> Case:
    """The case of ``params`` on ``base`` with ``fixed`` (the ``[set]`` that is valid only with a case's keys)."""
    try:
        return Case(index, params, base.replace(**{**fixed, **params}))
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


def _refuse_same_scenes(cases: tuple[Case, ...], owner: dict) -> None:
    """Refuse two valid cases whose scenes are equal though written differently (``1`` and ``1.0``)."""
    first: dict[str, Case] = {}
    for case in cases:
        if case.scene is None:
            continue
        a = first.setdefault(case.id, case)
        if a is not case:
            keys = dict.fromkeys([*a.params, *case.params])
            differ = [k for k in keys if k not in a.params or k not in case.params
                      or as_text(a.params[k]) != as_text(case.params[k])] or list(keys)
            field_name = f"{owner[differ[0]]}.{differ[0]}" if len(differ) == 1 else _where(a, owner, differ)
            raise StudyError(f"{field_name}: cases {a.index} ({shown(a.params, differ)}) and {case.index} "
                             f"({shown(case.params, differ)}) give the same scene (give each case once)")


def _names(error: str, key: str) -> bool:
    """Whether a scene error names ``key`` or a table on its path (e.g. ``contact`` for ``contact.friction``)."""
    field_name = error.split(":", 1)[0]
    return key == field_name or key.startswith(field_name + ".")


def _where(case: Case, owner: dict, keys=None) -> str:
    return "/".join(dict.fromkeys(owner[k] for k in keys or case.params))


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


def _name(name: Any) -> str:
    """The study's name, checked by the rule and message of a scene's name (it names a folder: no path)."""
    try:
        Scene.from_dict({"name": name})
    except SceneError as err:
        raise StudyError(str(err)) from None
    return name


def _outputs(names: Any) -> tuple[str, ...]:
    if names is None:
        return tuple(OUTPUTS)
    if not isinstance(names, list) or not names:
        raise StudyError(f"outputs: must be a non-empty list of output names (got {names!r})")
    for name in names:
        if name not in OUTPUTS:
            raise StudyError(f"outputs: unknown output {name!r} (allowed: {', '.join(OUTPUTS)})")
    return tuple(dict.fromkeys(names))
