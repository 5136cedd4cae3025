"""Rules across scene keys: vector lengths by dimension, boundary names by geometry, ranges set by other keys.

:func:`check` runs after every key has been validated on its own; each rule raises a
:class:`~ngwear.model.keys.SceneError` naming the key that is off and what it must be.  Quantities derived from
several keys (α = κ‖v*‖, k = T/N, k·α·L, the loads) must stay finite: a scene that overflows them is refused.
"""
from __future__ import annotations

import math
from pathlib import Path

from .coefficients import NAMES, bound, describe, state_of
from .compliance import COMPLIANCES, largest_slope
from .keys import SceneError, range_text
from .kinds import KINDS, check_features, owners
from .materials import LAWS, check_table
from .wear_laws import WEAR_LAWS
from .wear_laws import constants as wear_constants


def check(scene) -> None:
    """Every rule of this module, in the order a reader fixes a scene: geometry first, time last."""
    _check_geometry(scene)
    _check_material(scene)
    _check_contact(scene)
    _check_motion(scene)
    _check_loads(scene)
    _check_time(scene)
    _check_heat(scene)
    _check_programme(scene)
    _check_load_sizes(scene)
    if scene.solver.method == "full" and scene.wear.integrator != "explicit":
        raise SceneError(f"solver.method: 'full' supports only wear.integrator = 'explicit' "
                         f"(got {scene.wear.integrator!r}; use solver.method = 'condensed')")


def vector(value, name: str, dim: int) -> tuple[float, ...]:
    """``value`` if it is a list of ``dim`` numbers, else a SceneError naming ``name``."""
    if value is None or len(value) != dim:
        raise SceneError(f"{name}: must be a list of {dim} numbers (got {list(value) if value else value!r})")
    return value


def _value(scene, dotted: str):
    node = scene
    for part in dotted.split("."):
        node = getattr(node, part)
    return node


# ---------------------------------------------------------------- geometry and mesh


def _check_geometry(scene) -> None:
    g, m, kind = scene.geometry, scene.mesh, KINDS[scene.geometry.kind]
    for option in {o for k in KINDS.values() for o in k.options}:
        if _value(scene, option) is not None and g.kind not in owners(option):
            allowed = " or ".join(repr(name) for name in owners(option))
            raise SceneError(f"{option}: only for geometry.kind = {allowed} (got kind {g.kind!r})")
    _check_size(g, kind)
    boundaries = g.boundaries
    if "contact" not in boundaries:
        raise SceneError(f"geometry.file: {Path(g.file).name} has no boundary named 'contact' (its named "
                         f"boundaries: {', '.join(boundaries) or 'none'})")
    if not g.dirichlet and scene.loads.plate is None:
        raise SceneError("geometry.dirichlet: must name at least one boundary, or give loads.plate (a rigid plate "
                         "pressed along contact.direction) to hold the body (got [])")
    for b in g.dirichlet:
        if b not in boundaries or b == "contact":
            allowed = ", ".join(x for x in boundaries if x != "contact")
            raise SceneError(f"geometry.dirichlet: unknown or non-Dirichlet boundary {b!r} (allowed: {allowed})")
    sizes = ("maxh", "contact_maxh", "grading", "contact_zone", "zone_center")
    if kind.build is None:
        if any(getattr(m, name) is not None for name in sizes):
            raise SceneError(f"mesh.maxh: not used with geometry.kind = {g.kind!r} (the file is the mesh; leave "
                             f"{', '.join(f'mesh.{name}' for name in sizes)} out)")
        return
    if not 0 < m.maxh <= g.extent:
        raise SceneError(f"mesh.maxh: must be {range_text(0, round(g.extent, 6), lo_open=True)} (got {m.maxh!r})")
    if m.contact_maxh is not None and not 0 < m.contact_maxh <= m.maxh:
        raise SceneError(f"mesh.contact_maxh: must be {range_text(0, m.maxh, lo_open=True)} (got {m.contact_maxh!r})")
    if m.contact_zone is not None and not 0 < m.contact_zone <= g.extent:
        raise SceneError(f"mesh.contact_zone: must be {range_text(0, round(g.extent, 6), lo_open=True)} "
                         f"(got {m.contact_zone!r})")
    for name in ("contact_zone", "zone_center"):
        if getattr(m, name) is not None and m.contact_maxh is None:
            raise SceneError(f"mesh.{name}: only with mesh.contact_maxh, the size within the zone")
    if m.zone_center is not None:
        if m.contact_zone is None and KINDS[g.kind].zone is None:
            raise SceneError("mesh.zone_center: only with mesh.contact_zone, the radius of the zone")
        vector(m.zone_center, "mesh.zone_center", g.dim)


def _check_size(g, kind) -> None:
    """The size of a built-in kind: its length, positive lengths, then the kind's own rules; none for a file."""
    if kind.size is None:
        if g.size is not None:
            raise SceneError(f"geometry.size: not used with geometry.kind = {g.kind!r} (the file gives the shape)")
        return
    if len(g.size) != len(kind.size):
        raise SceneError(f"geometry.size: must be a list of {len(kind.size)} numbers (got {list(g.size)})")
    if min(g.size) <= 0:
        raise SceneError(f"geometry.size: every length must be > 0 (got {list(g.size)})")
    if kind.check is not None:
        kind.check(g)
    if g.backing is not None:
        check_features("geometry.backing", g.backing, {"backing": g.backing}, g.extent)


# ---------------------------------------------------------------- material and contact


def _check_material(scene) -> None:
    """Each region's material (its table over ``[material]``) fits its law and is positive definite; regions exist."""
    material, regions = scene.material, scene.geometry.regions
    for name in material.regions:
        if name not in regions:
            raise SceneError(f"material.regions.{name}: unknown region (the part's regions: {', '.join(regions)})")
    if not material.given:
        bare = [r for r in regions if r not in material.regions or not material.regions[r].given]
        if bare:
            raise SceneError(f"material.regions.{bare[0]}: missing (give its constants, or constants in [material] "
                             "for every region without a table)")
    tables = ({"material": material} if material.given else {}) | {
        f"material.regions.{name}" if name in material.regions else "material": table
        for name, table in material.by_region(regions).items()}
    for key, table in tables.items():
        check_table(table, key)
        LAWS[table.kind].check(table, scene.dim, scene.contact.direction or (0.0,) * (scene.dim - 1) + (-1.0,), key)
        if table.axis is not None:
            vector(table.axis, f"{key}.axis", scene.dim)


def _check_contact(scene) -> None:
    c = scene.contact
    vector(c.direction, "contact.direction", scene.dim)
    for constant in [k for law in COMPLIANCES.values() for k in law.constants if k not in COMPLIANCES[c.law].constants]:
        value = getattr(c, constant.name)
        if value != constant.default:       # another law's key
            raise SceneError(f"contact.{constant.name}: must be {constant.default:g} with contact.law = {c.law!r} "
                             f"(got {value!r})")
    for constant in [k for k in wear_constants() if k not in WEAR_LAWS[c.wear_law].constants]:
        value = getattr(c, constant.name)
        if value != constant.default:       # another wear law's key
            owner = next(law.name for law in WEAR_LAWS.values() if constant in law.constants)
            shown = list(value) if isinstance(value, tuple) else value
            raise SceneError(f"contact.{constant.name}: only with contact.wear_law = {owner!r} (got {shown} with "
                             f"contact.wear_law = {c.wear_law!r})")
    WEAR_LAWS[c.wear_law].check(c)
    slope = largest_slope(c)
    if slope is not None and not slope <= BIG:
        raise SceneError(f"contact.stiffness: the layer's largest slope L·e·g^(e−1) must be <= {BIG:g} (got L = "
                         f"{describe(c.stiffness)}, e = {c.exponent:g}, g = {c.gap:g})")


# ---------------------------------------------------------------- foundation motion


def _check_motion(scene) -> None:
    f, c, T, nu = scene.foundation, scene.contact, scene.time.T, scene.contact.direction
    velocity = vector(f.velocity, "foundation.velocity", scene.dim)
    if f.center is not None:
        vector(f.center, "foundation.center", scene.dim)
    omega = f.angular_velocity
    if scene.dim == 2 and isinstance(omega, tuple):
        raise SceneError(f"foundation.angular_velocity: must be a number in 2D (got {list(omega)})")
    if scene.dim == 3 and omega is not None and (not isinstance(omega, tuple) or len(omega) != 3):
        raise SceneError(f"foundation.angular_velocity: must be a list of 3 numbers in 3D (got {omega!r})")
    _check_table(f.speed_table, "foundation.speed_table", T)
    vn = sum(a * b for a, b in zip(velocity, nu))
    speed = math.hypot(*velocity)
    tangential = math.hypot(*(v - vn * n for v, n in zip(velocity, nu)))
    # a rotation slides Γ_C over the foundation when its axis is not parallel to the contact plane
    spin = abs(omega or 0.0) if scene.dim == 2 else abs(sum(a * b for a, b in zip(omega or (0, 0, 0), nu)))
    if (bound(c.friction) or 0) > 0 and tangential <= 1e-12 * speed and spin == 0:
        raise SceneError("foundation.velocity: must have a non-zero part tangential to contact.direction "
                         "(or give foundation.angular_velocity about an axis along it) when contact.friction > 0 "
                         f"(got {list(velocity)})")
    if (bound(c.wear) or 0) > 0 and speed == 0 and spin == 0:
        raise SceneError("foundation.velocity: must be non-zero (or give foundation.angular_velocity) when "
                         f"contact.wear > 0 (got {list(velocity)})")
    _check_rates(scene)


def _check_rates(scene) -> None:
    """The foundation's largest speed at the part and κ‖v*‖·L_p·T stay below :data:`BIG` (finite, with room)."""
    f, c = scene.foundation, scene.contact
    factor = max((abs(s) for _, s in f.speed_table), default=1.0)
    omega = f.angular_velocity or 0.0
    spin = math.hypot(*omega) if isinstance(omega, tuple) else abs(omega)
    translation, rotation = math.hypot(*f.velocity), spin * _reach(scene)
    slide = factor * (translation + rotation)
    if not slide <= BIG:
        name = "foundation.angular_velocity" if rotation > translation else "foundation.velocity"
        raise SceneError(f"{name}: the foundation's largest speed at the part, {slide:.3g}, must be <= {BIG:g}")
    wear, slope = bound(c.wear), largest_slope(c)
    rate = None if wear is None or slope is None else wear * slide * slope * scene.time.T
    if rate is not None and not rate <= BIG:
        raise SceneError(f"contact.wear: κ‖v*‖·L·T = {rate:.3g} must be <= {BIG:g} (the wear of a run this fast "
                         f"overflows; κ = {describe(c.wear)})")


def _reach(scene) -> float:
    """A bound of the distance of the part's points from the rotation axis: |c| + the part's reach from the origin."""
    g = scene.geometry
    center = math.hypot(*(scene.foundation.center or (0.0,)))
    offset = math.hypot(*g.position) if g.position is not None else 0.0
    return center + offset + 2 * g.extent


BIG = 1e150
"""Largest sliding speed, and largest κ‖v*‖·L·T, a scene may give: their squares and products in a run stay finite."""


def _check_table(table, name: str, T: float) -> None:
    times = [t for t, _ in table]
    if any(b < a for a, b in zip(times, times[1:])):
        raise SceneError(f"{name}: times must be non-decreasing (got {times})")
    if table and (times[0] > 0 or times[-1] < T):
        raise SceneError(f"{name}: must cover [0, time.T] = [0, {T}] (got {times[0]} to {times[-1]})")


# ---------------------------------------------------------------- loads


def _check_loads(scene) -> None:
    loads, g = scene.loads, scene.geometry
    boundaries = g.boundaries
    for bname, vec in loads.traction.items():
        if bname not in boundaries or bname == "contact" or bname in g.dirichlet:
            allowed = ", ".join(x for x in boundaries if x != "contact" and x not in g.dirichlet)
            raise SceneError(f"loads.traction.{bname}: unknown or non-Neumann boundary (allowed: {allowed})")
        vector(vec, f"loads.traction.{bname}", scene.dim)
    if loads.body_force is not None:
        vector(loads.body_force, "loads.body_force", scene.dim)
    _check_table(loads.time_table, "loads.time_table", scene.time.T)
    if loads.plate is not None:
        _check_plate(scene, boundaries)


def _check_load_sizes(scene) -> None:
    """Each load times its largest factor (``loads.time_table``, a programme's ``load``) <= :data:`BIG` (no overflow)."""
    loads, programme = scene.loads, scene.programme
    factors = ([abs(f) for b in programme.blocks for f in b.load] if programme is not None else
               [abs(f) for _, f in loads.time_table])
    factor = max(factors, default=1.0)
    scaled = (f" times the largest load factor ({'the programme' if programme is not None else 'loads.time_table'}"
              f", {factor:g})" if factor != 1.0 else "")
    given = {**{f"loads.traction.{name}": vec for name, vec in loads.traction.items()},
             "loads.body_force": loads.body_force, "loads.plate.force": loads.plate and loads.plate.force}
    for name, vec in ((name, vec) for name, vec in given.items() if vec is not None):
        size = max(abs(v) for v in vec) * factor
        if not size <= BIG:
            raise SceneError(f"{name}: its largest component{scaled} is {size:.3g}; must be <= {BIG:g} (the forces "
                             f"of a run this large overflow; got {list(vec)})")


def _check_plate(scene, boundaries: tuple[str, ...]) -> None:
    plate, g = scene.loads.plate, scene.geometry
    taken = {"contact", *g.dirichlet, *scene.loads.traction}
    if plate.boundary not in boundaries or plate.boundary in taken:
        allowed = ", ".join(b for b in boundaries if b not in taken)
        raise SceneError(f"loads.plate.boundary: unknown, clamped, loaded or contact boundary {plate.boundary!r} "
                         f"(allowed: {allowed})")
    force = vector(plate.force, "loads.plate.force", scene.dim)
    pressing = sum(f * n for f, n in zip(force, scene.contact.direction))
    floating = not g.dirichlet
    if floating and pressing <= 0:
        raise SceneError(f"loads.plate.force: must press the body onto the foundation (a positive component along "
                         f"contact.direction) when nothing is clamped (got {list(force)})")
    if floating and any(f < 0 for _, f in scene.loads.time_table):
        raise SceneError("loads.time_table: factors must be >= 0 when only the plate holds the body (a pulling "
                         "plate would lift the body off)")


# ---------------------------------------------------------------- time and output


def _check_time(scene) -> None:
    t, o = scene.time, scene.output
    if not math.isfinite(t.T / t.steps) or t.T / t.steps == 0:
        raise SceneError(f"time.T: the step T/N = {t.T / t.steps:.3g} is not a usable number (got T = {t.T:g})")
    if not t.adaptive:
        given = [k for k in ("min_step", "max_step") if getattr(t, k) is not None]
        if given:
            raise SceneError(f"time.{given[0]}: only with time.adaptive = true")
    elif not 0 < t.min_step <= t.max_step <= t.T:
        raise SceneError(f"time.max_step: must satisfy 0 < time.min_step <= time.max_step <= time.T = {t.T} "
                         f"(got {t.min_step!r}, {t.max_step!r})")
    if o.times is not None:
        if not o.times or any(b <= a for a, b in zip(o.times, o.times[1:])) or o.times[0] < 0 or o.times[-1] > t.T:
            raise SceneError(f"output.times: must be increasing times in [0, time.T] = [0, {t.T}] (got {list(o.times)})")
    elif not 0 < o.every <= t.T:
        raise SceneError(f"output.every: must be a time in (0, time.T] = (0, {t.T}] (got {o.every!r})")
    frames = frame_count(scene)
    if frames > o.max_frames:
        name, given = ("output.times", f"{len(o.times)} times") if o.times is not None else ("output.every", f"{o.every:g}")
        fewer = "fewer times" if o.times is not None else f"output.every >= {t.T / (o.max_frames - 1 or 1):.3g}"
        raise SceneError(f"{name}: {given} gives {_count(frames)} frames, more than output.max_frames = {o.max_frames} "
                         f"(each a full field in memory and a VTU file); give {fewer}, or raise output.max_frames")


def frame_count(scene) -> float:
    """The frames a run writes at most: one per output time up to T and the last step, each a step of the run.

    A uniform run writes at most its steps + 1 (an output time between steps takes the nearest one); an adaptive
    run ends a step on every output time.  A float: T/every may pass any integer (1e300 / 1e-9).
    """
    o, t = scene.output, scene.time
    if o.times is not None:
        times = len(o.times) + (o.times[-1] < t.T)
    else:
        ratio = t.T / o.every
        if not math.isfinite(ratio):
            return math.inf if t.adaptive else t.steps + 1
        k = math.floor(ratio * (1 + 1e-12))                                 # output times k·every ≤ T: k + 1
        times = k + 1 + (k < ratio * (1 - 1e-12))                           # and the last step, unless on one
    return times if t.adaptive else min(times, t.steps + 1)


def _count(number: float) -> str:
    return f"{number:.3g}" if number >= 1e9 else f"{int(number)}"


# ---------------------------------------------------------------- heat


def _check_heat(scene) -> None:
    """A coefficient of T needs the temperature; ``conduction`` needs k, ρ, c everywhere, η and a counterface."""
    h, f = scene.heat, scene.foundation
    if h.model == "none":
        for name in NAMES:
            if "T" in state_of(getattr(scene.contact, name), name):
                raise SceneError(f"contact.{name}: depends on the temperature T: needs heat.model = 'conduction' "
                                 f"(got {h.model!r})")
        return
    material = scene.material
    for region, table in material.by_region(scene.geometry.regions).items():
        owner = f"material.regions.{region}" if region in material.regions else "material"
        for name in ("conductivity", "heat_capacity", "density"):
            if getattr(table, name) is None:
                raise SceneError(f"{owner}.{name}: missing (heat.model = 'conduction' needs conductivity, "
                                 "heat_capacity and density on every region)")
        if table.expansion and table.kind == "energy" and scene.dim == 2:
            raise SceneError(f"{owner}.expansion: not for material.law = 'energy' in 2D (ψ of the in-plane strain "
                             "has no out-of-plane stiffness for the plane-strain thermal stress)")
    if h.partition is None and h.interface == "partition":
        raise SceneError("heat.partition: missing (heat.model = 'conduction' needs the body's share η of the "
                         "frictional heat: a number in [0, 1] or 'effusivity')")
    if (h.interface == "conductance") != (h.contact_conductance is not None):
        needs = "missing (heat.interface = 'conductance' needs h_c >= 0)" if h.contact_conductance is None else \
            "only with heat.interface = 'conductance'"
        raise SceneError(f"heat.contact_conductance: {needs}")
    if h.partition == "effusivity":
        for name in ("conductivity", "density", "heat_capacity"):
            if getattr(f, name) is None:
                raise SceneError(f"foundation.{name}: missing (heat.partition = 'effusivity' needs the "
                                 "counterface's conductivity, density and heat_capacity)")
    boundaries, seen = scene.geometry.boundaries, set()
    for i, entry in enumerate(h.convection):
        if entry.boundary not in boundaries or entry.boundary == "contact" or entry.boundary in seen:
            allowed = ", ".join(b for b in boundaries if b != "contact" and b not in seen)
            raise SceneError(f"heat.convection[{i}].boundary: unknown, contact or repeated boundary "
                             f"{entry.boundary!r} (allowed: {allowed})")
        seen.add(entry.boundary)
    _check_counterface(f, scene.time.T)


def _check_counterface(f, T: float) -> None:
    """A given temperature (a number or a table over [0, T]) or a lumped disc with its cooling, not both."""
    if f.thermal_mass is not None:
        if f.temperature is not None:
            raise SceneError("foundation.temperature: not with foundation.thermal_mass (a lumped counterface's "
                             "temperature is computed; give one of them)")
        if f.cooling is None:
            raise SceneError("foundation.cooling: missing (a lumped counterface, foundation.thermal_mass, needs its "
                             "cooling H_d >= 0)")
    elif f.cooling is not None:
        raise SceneError("foundation.cooling: only with foundation.thermal_mass (a lumped counterface)")
    if isinstance(f.temperature, tuple):
        _check_table(f.temperature, "foundation.temperature", T)


def _check_programme(scene) -> None:
    """A programme's factors replace the time tables; a body held by the plate alone is never pulled off."""
    if scene.programme is None:
        return
    for name in ("foundation.speed_table", "loads.time_table"):
        if _value(scene, name):
            raise SceneError(f"{name}: not with a [programme] (its stops' speed and load factors replace the time "
                             "tables); leave it out")
    if scene.time.adaptive:
        raise SceneError("time.adaptive: not with a [programme] yet (a stop takes programme.steps_per_stop uniform "
                         "steps); leave it out")
    if not scene.geometry.dirichlet:
        for i, block in enumerate(scene.programme.blocks, start=1):
            if min(block.load) < 0:
                raise SceneError(f"programme.stops: block {i}: load: factors must be >= 0 when only the plate holds "
                                 f"the body (got {list(block.load)})")
