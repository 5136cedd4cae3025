"""Scenes: plain frozen data describing one contact-with-wear simulation.

A scene is read from TOML with nested tables (``[geometry]``, ``[mesh]``, ``[material]``, ``[contact]``,
``[foundation]``, ``[loads]``, ``[time]``, ``[wear]``, ``[heat]``, ``[solver]``, ``[output]``, ``[programme]``) and
two top-level keys (``name``, ``units``), each key declared once in :mod:`ngwear.model.sections`.
:meth:`Scene.from_dict` first keeps the tables as given (a part given in Python becomes a cached file, the files are
resolved), then fills the defaults that depend on the kind and on other keys (a programme sets ``time.T`` and
``time.steps``), then pydantic validates every key against its declaration and :mod:`ngwear.model.rules` checks the
rules across keys; the first violation is one :class:`SceneError` line naming the dotted key.
``Scene.replace(**{"time.steps": 10})`` overrides keys with the dotted keys that ``ngwear run --set time.steps=10``
accepts, and ``load_scene(path, overrides)`` a file's: both apply the overrides to the keys as given and fill the
defaults after them, so an override both escapes a default that depends on other keys (``foundation.velocity`` once
``foundation.angular_velocity`` is given) and repairs a bad value of the file.  :meth:`Scene.changed_from` tells what
a change of scene invalidates, from the levels the keys declare.
"""
from __future__ import annotations

import copy
import json
import tomllib
from pathlib import Path
from typing import Any

from pydantic import ConfigDict, PrivateAttr, ValidationError, model_validator

from . import examples, function_tokens, messages, rules, user_parts
from .keys import MAX_ROWS, Level, SceneError, level_of
from .kinds import KINDS
from .materials import default_constants
from .programme import MAX_STEPS
from .sections import (
    Contact,
    Foundation,
    Geometry,
    HeatSpec,
    Loads,
    Material,
    MeshSpec,
    Output,
    Programme,
    SolverSpec,
    TimeGrid,
    TopLevel,
    WearSpec,
    declared_keys,
)

__all__ = ["Level", "Scene", "SceneError", "json_schema", "load_scene", "parse_override", "set_dotted"]


class Scene(TopLevel):
    """A complete, validated simulation set-up.  Build with :func:`load_scene` or :meth:`from_dict`.

    Frozen: :meth:`replace` gives a changed copy.  The reference of every key is ``docs/reference/scene.md``
    (generated from :mod:`ngwear.model.sections`).

    Attributes
    ----------
    name : str
        The scene's name (output folder, titles).
    units : {"SI"} or None
        The unit system of its numbers (None: dimensionless).
    geometry, mesh, material, contact, foundation, loads, time, wear, heat, solver, output : Section
        The scene file's tables, with their keys as attributes (``scene.contact.friction``).
    programme : Programme or None
        A braking programme (``[programme]``), which sets ``time.T`` and ``time.steps``.
    dim : int
        2 or 3.
    dt : float
        The uniform step T / steps; with a programme the longest step of a stop (a dwell is one step, no wear).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    _given: dict | None = PrivateAttr(default=None)     # the tables as given, before the defaults (replace's base)

    geometry: Geometry = Geometry()
    mesh: MeshSpec = MeshSpec()
    material: Material = Material()
    contact: Contact = Contact()
    foundation: Foundation = Foundation()
    loads: Loads = Loads()
    time: TimeGrid = TimeGrid()
    wear: WearSpec = WearSpec()
    heat: HeatSpec = HeatSpec()
    solver: SolverSpec = SolverSpec()
    output: Output = Output()
    programme: Programme | None = None

    @property
    def dim(self) -> int:
        return self.geometry.dim

    @property
    def dt(self) -> float:
        if self.programme is not None:
            return max(b.duration for b in self.programme.blocks) / self.programme.steps_per_stop
        return self.time.T / self.time.steps

    def __eq__(self, other) -> bool:
        """The same keys' values (however they were given: a default filled or the same value named)."""
        return isinstance(other, Scene) and self.__dict__ == other.__dict__

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> Scene:
        """Validate a nested dict (as read from TOML) into a Scene: the keys as given, then the defaults."""
        if not isinstance(data, dict):
            raise SceneError("scene: must be a table")
        _check_nesting(data)
        given = _given(data)
        data = _prepared(copy.deepcopy(given))
        try:
            scene = cls.model_validate(data)
        except ValidationError as err:
            errors = sorted(err.errors(), key=lambda e: e["type"] != "extra_forbidden")  # a typo first
            raise SceneError(messages.message(errors[0], data, cls)) from None
        scene._given = given
        return scene

    def to_dict(self) -> dict[str, Any]:
        """The nested-dict form that :meth:`from_dict` and TOML use (``wear.integrator`` only where it was named)."""
        data = self.model_dump(mode="json", exclude_none=True)
        if "integrator" not in self.wear.model_fields_set:
            data["wear"].pop("integrator")
        if self.programme is not None:
            _follow_programme(data)
        return data

    def replace(self, **dotted: Any) -> Scene:
        """A new scene with keys overridden by dotted keys, e.g. ``replace(**{"time.steps": 10})``.

        The overrides apply to the keys as given (a scene made from a complete table, as ``scene.json`` holds it: all
        of them), and the defaults are filled after them.  A programme given here sets ``time.T`` and ``time.steps``
        (unless they are given too: that is refused).
        """
        return _overridden(copy.deepcopy(self._given) if self._given is not None else self.to_dict(), dotted)

    def value(self, dotted: str) -> Any:
        """The value of a dotted scene key (None where a table, e.g. ``loads.plate``, is absent)."""
        node = self
        for part in dotted.split("."):
            node = getattr(node, part, None)
        return node

    def signature(self, level: Level, by_content: bool = False) -> str:
        """The values of the keys declared at ``level``, as one string.

        A part file stands for its content: by its path, size and mtime (:func:`~ngwear.model.user_parts.fingerprint`,
        cheap, for comparing scenes in one session), or ``by_content``, by its bytes' hash alone
        (:func:`~ngwear.model.user_parts.content_hash`, for what outlives the file's place: the mesh cache).
        """
        values = {name: self.value(name) for name, info in declared_keys() if level_of(info) == level}
        if values.get("geometry.file") is not None:
            identify = user_parts.content_hash if by_content else user_parts.fingerprint
            values["geometry.file"] = identify(values["geometry.file"])
        return json.dumps(values, sort_keys=True, default=list)

    def changed_from(self, other: Scene) -> Level:
        """The first level (of :class:`Level`) whose keys differ from ``other``'s: what the change invalidates."""
        return next((level for level in Level if level is not Level.NOTHING
                     and self.signature(level) != other.signature(level)), Level.NOTHING)

    @model_validator(mode="after")
    def _cross_checks(self) -> Scene:
        if self.wear.integrator is None:    # not named: the paper's explicit scheme, trapezoidal for adaptive steps
            adaptive = self.time.adaptive and self.solver.method == "condensed"
            resolved = WearSpec.model_construct(set(self.wear.model_fields_set), **{
                **self.wear.__dict__, "integrator": "trapezoidal" if adaptive else "explicit"})
            object.__setattr__(self, "wear", resolved)   # a new WearSpec: the field's default one is shared
        rules.check(self)
        return self


def load_scene(path: str | Path, overrides: dict[str, Any] | None = None) -> Scene:
    """Read and validate a scene TOML file, or a shipped scene by name.

    Parameters
    ----------
    path : str or Path
        A scene file, or the name of a shipped scene (``"paper_strip"``, see ``ngwear examples``).
    overrides : dict, optional
        Dotted keys and values (``{"contact.gap": 0.001}``, what ``--set`` gives) applied to the file's keys before
        its defaults are filled and before it is validated: they may repair a value of the file.

    Returns
    -------
    Scene
        The validated scene; its ``name`` is the file's stem unless the file names it.

    Raises
    ------
    SceneError
        The file is missing, unreadable or not TOML, or a key is missing, of the wrong type or out of range
        (one line naming the dotted key and its allowed range).
    """
    path = examples.find(path)
    try:
        if path.stat().st_size > MAX_FILE:
            raise SceneError(f"scene file: {path} is {path.stat().st_size / 2**20:.3g} MB, more than a scene file's "
                             f"{MAX_FILE // 2**20} MB (a table of {MAX_ROWS} rows takes 0.2 MB)")
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise SceneError(f"scene file: cannot read {path} ({err})") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"scene file: {path} is not valid TOML ({err})") from None
    except RecursionError:
        raise SceneError(f"scene file: {path} is nested too deeply to read (more than {MAX_NESTING} levels are "
                         "refused)") from None
    if not data and not overrides:
        raise SceneError(f"scene file: {path} holds no keys (a scene names at least its part, e.g. [geometry] "
                         "kind = \"strip\")")
    data.setdefault("name", path.stem)
    geometry = data.get("geometry")
    if isinstance(geometry, dict) and isinstance(geometry.get("file"), str):
        geometry["file"] = str(path.parent / Path(geometry["file"]).expanduser())   # relative to the scene file
    programme = data.get("programme")
    if isinstance(programme, dict) and isinstance(programme.get("file"), str):
        programme["file"] = str(path.parent / Path(programme["file"]).expanduser())
    return _overridden(data, overrides or {})


def _overridden(data: dict[str, Any], dotted: dict[str, Any]) -> Scene:
    """The scene of the tables ``data`` with the dotted keys set (a programme set there sets the time), then filled."""
    if any(name.split(".")[0] == "programme" for name in dotted):
        _follow_programme(data)
    for name, value in dotted.items():
        set_dotted(data, name, value)
    return Scene.from_dict(data)


def set_dotted(data: dict[str, Any], name: str, value: Any) -> None:
    """Set ``data["a"]["b"] = value`` for ``name = "a.b"``; unknown sections are rejected later."""
    parts = name.split(".")
    node = data
    for part in parts[:-1]:
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise SceneError(f"{name}: '{part}' is not a table")
        node = child
    node[parts[-1]] = value


def parse_override(text: str) -> tuple[str, Any]:
    """``"mesh.maxh=0.05"`` → ``("mesh.maxh", 0.05)``; the value is read as a TOML value."""
    name, sep, raw = text.partition("=")
    if not sep or not name.strip():
        raise SceneError(f"--set {text}: expected KEY=VALUE, e.g. time.steps=10")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    except RecursionError:
        raise SceneError(f"{name.strip()}: nested too deeply to read (more than {MAX_NESTING} levels are "
                         "refused)") from None
    return name.strip(), value


def json_schema() -> dict[str, Any]:
    """The scene schema as JSON Schema (for editors that complete and check scene files)."""
    return messages.json_schema(Scene)


# ---------------------------------------------------------------- before validation

MAX_NESTING = 10
"""Deepest nesting of tables and lists a scene may have (its deepest key, ``material.regions.NAME.axis``, has 5)."""
MAX_FILE = 2**20
"""Largest scene file read (bytes): parsing TOML takes time in proportion to the numbers, before any key is checked."""


def _check_nesting(data: dict[str, Any]) -> None:
    """Refuse, naming the key, tables or lists nested deeper than :data:`MAX_NESTING` (walked without recursion)."""
    stack = [(data, "scene", 0)]
    while stack:
        node, name, depth = stack.pop()
        if depth > MAX_NESTING:
            raise SceneError(f"{name}: nested deeper than {MAX_NESTING} levels")
        if isinstance(node, dict):
            stack.extend((value, str(k) if name == "scene" else f"{name}.{k}", depth + 1) for k, value in node.items()
                         if isinstance(value, (dict, list, tuple)))
        elif isinstance(node, (list, tuple)):
            stack.extend((value, name, depth + 1) for value in node if isinstance(value, (dict, list, tuple)))


def _given(data: dict[str, Any]) -> dict[str, Any]:
    """The raw tables as given, each a copy: a Python part stored, a function kept by its token, the files resolved."""
    data = {name: dict(v) if isinstance(v, dict) else v for name, v in data.items()}
    g = data.get("geometry", {})
    if isinstance(g, dict) and "shape" in g:
        _store_shape(g)                         # a netgen shape is no data to copy: its cached file is
    data = copy.deepcopy(data)
    function_tokens.tokenised(data)
    g = data.get("geometry", {})
    if isinstance(g, dict) and isinstance(g.get("file"), str) and g["file"]:
        g["file"] = str(Path(g["file"]).expanduser().resolve())
    table = data.get("programme")
    if isinstance(table, dict) and isinstance(table.get("file"), str):
        table["file"] = str(Path(table["file"]).expanduser().resolve())
    return data


def _prepared(data: dict[str, Any]) -> dict[str, Any]:
    """The given tables (:func:`_given`, changed here) with the defaults that depend on the kind and on other keys."""
    g = data.get("geometry", {})
    name = g.get("kind", "strip") if isinstance(g, dict) else None
    kind = KINDS.get(name) if isinstance(name, str) else None
    if kind is None:
        return data
    part = _part(g) if kind.from_file else None
    dim = kind.dim or part.dim
    if kind.size is not None:
        _default(data, "geometry", "size", list(kind.size))
    if kind.defaults is not None:
        kind.defaults(g)
    if kind.build is not None:
        _default(data, "mesh", "maxh", 0.1 if part is None else float(f"{part.extent / 10:.2g}"))
    _default(data, "geometry", "dirichlet", list(kind.dirichlet))
    _default(data, "contact", "direction", [0.0] * (dim - 1) + [-1.0])
    foundation = data.get("foundation", {}) if isinstance(data.get("foundation", {}), dict) else {}
    turning = foundation.get("angular_velocity") is not None      # a disc: no translation unless it is given
    _default(data, "foundation", "velocity", [0.0] * dim if turning else [1.0] + [0.0] * (dim - 1))
    material = data.get("material", {})
    if isinstance(material, dict) and not material.get("regions"):     # the paper's dimensionless λ = η = 1
        for name, value in default_constants(material).items():
            _default(data, "material", name, value)
    _time_of_programme(data)
    time = data.get("time", {}) if isinstance(data.get("time", {}), dict) else {}
    final = time.get("T", 1.0)
    if isinstance(final, (int, float)) and not isinstance(final, bool) and final > 0:
        if not isinstance(data.get("output", {}), dict) or "times" not in data.get("output", {}):
            _default(data, "output", "every", final / 4)
        if time.get("adaptive"):
            _default(data, "time", "min_step", final * 1e-8)
            _default(data, "time", "max_step", final / 10)
    return data


def _follow_programme(data: dict[str, Any]) -> None:
    """Leave ``time.T`` and ``time.steps`` to the programme (a scene's dict as :meth:`Scene.to_dict` writes it)."""
    for name in ("T", "steps"):
        data.get("time", {}).pop(name, None)


def _time_of_programme(data: dict[str, Any]) -> None:
    """A programme's file resolved, and ``time.T`` and ``time.steps`` set from it (refused when given too).

    A programme that does not validate is left as it is: validation names its key.
    """
    table = data.get("programme")
    if not isinstance(table, dict):
        return
    time = data.setdefault("time", {})
    if not isinstance(time, dict):
        return
    for name, instead in (("T", "the sum of its stops and dwells"), ("steps", "programme.steps_per_stop per stop")):
        if name in time:
            raise SceneError(f"time.{name}: set by the programme ({instead}); leave time.{name} out "
                             f"(got {time[name]!r})")
    try:
        programme = Programme.model_validate(table)
    except ValidationError:
        return
    if programme.steps > MAX_STEPS:
        raise SceneError(f"programme.steps_per_stop: the programme's stops take {programme.steps} steps "
                         f"(stops × steps_per_stop), more than {MAX_STEPS}; use fewer steps per stop or stops")
    time["T"], time["steps"] = programme.end, programme.steps


def _default(data: dict, section: str, name: str, value: Any) -> None:
    """Fill a key that depends on others where it is not given (or given as None: "the default")."""
    sec = data.setdefault(section, {})
    if isinstance(sec, dict) and sec.get(name) is None:
        sec[name] = value


def _store_shape(g: dict) -> None:
    """``geometry.shape`` (a netgen.occ shape or a mesh, Python only) becomes a cached part file."""
    try:
        g["kind"], g["file"] = user_parts.store(g.pop("shape"))
    except user_parts.PartError as err:
        raise SceneError(str(err)) from None
    g.pop("size", None)


def _part(g: dict) -> user_parts.Part:
    """The part file of a raw ``[geometry]`` table, read (its path resolved): one line naming geometry.file if not."""
    file = g.get("file")
    if not isinstance(file, str) or not file:
        raise SceneError(f"geometry.file: must name a file for geometry.kind = {g['kind']!r} (got {file!r})")
    try:
        return user_parts.describe(g["file"], g["kind"])
    except user_parts.PartError as err:
        raise SceneError(f"geometry.file: {err}") from None
