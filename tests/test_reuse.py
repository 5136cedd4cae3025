"""Skip rules: a scene change handed to an existing discretization rebuilds exactly what its keys declare.

For every scene key and every part kind it applies to, without a run: the change gives the level its keys declare
(``Scene.changed_from``, ``Discretization.reuse``), ``with_scene`` shares exactly the pieces below it (mesh, body,
factorisation, contact compliance, loads: by identity) and builds nothing expensive, and what the kept pieces hold
equals what a fresh discretization of the changed scene builds.  For a sample of the changes, deliberately chosen
(each level in 2D and 3D, and the tricky ones): the changed scene run on the old discretization gives bit for bit what
a fresh run gives.
"""
import shutil
from functools import cached_property
from pathlib import Path

import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model.keys import Level, level_of
from ngwear.model.kinds import KINDS
from ngwear.model.scene_mesh import build_mesh
from ngwear.model.sections import declared_keys
from ngwear.numerics import discrete
from ngwear.numerics.discrete import Discretization

SHIPPED = ROOT / "geometries"
BASES = {   # a small scene per part kind: (shipped scene, overrides)
    "strip": ("paper_strip.toml", {"mesh.maxh": 0.5, "loads.traction": {"top": [0.0, -0.1]},
                                   "wear.integrator": "trapezoidal"}),     # 3 explicit steps would diverge
    "box": ("box3d.toml", {"mesh.maxh": 0.3, "wear.integrator": "trapezoidal"}),
    "half_disk": ("hertz.toml", {"mesh.maxh": 0.3, "mesh.contact_maxh": 0.05, "mesh.contact_zone": 0.3,
                                 "mesh.grading": 0.3, "contact.gap": 0.01, "contact.friction": 0.2,
                                 "contact.wear": 0.5, "foundation.velocity": [1.0, 0.0]}),
    # the pad's friction material isotropic (the changes below derive from an isotropic one), on its steel backing
    "pad": ("brake_pad.toml", {"mesh.maxh": 0.02, "time.T": 3.0, "output.every": 1.5, "material": {
        "young": 1e9, "poisson": 0.25, "regions": {"backing": {"young": 2.1e11, "poisson": 0.3}}}}),
    "pin": ("pin_on_disc.toml", {"mesh.maxh": 0.005, "mesh.contact_maxh": 0.002, "time.T": 3.0,
                                 "output.every": 1.5}),
    "step": ("cad_pad.toml", {"mesh.maxh": 0.03, "time.T": 3.0, "output.every": 1.5}),
}
STEPS = 3


def scaled(value, factor):
    return [factor * v for v in value] if isinstance(value, (list, tuple)) else factor * value


def free_boundary(scene):
    """A named boundary that is neither contact nor clamped, loaded or under the plate (None if there is none)."""
    taken = {"contact", *scene.geometry.dirichlet, *scene.loads.traction,
             *((scene.loads.plate.boundary,) if scene.loads.plate else ())}
    return next((b for b in scene.geometry.boundaries if b not in taken), None)


def copy_of(file) -> Path:
    """The name of the file's copy beside it (the base fixture makes it)."""
    return Path(file).with_stem(Path(file).stem + "-copy")


def geometry(scene, **changes):
    table = {k: v for k, v in scene.to_dict()["geometry"].items() if k not in changes or changes[k] is not None}
    return {"geometry": {**table, **{k: v for k, v in changes.items() if v is not None}}}


def young(scene) -> float:
    """The scene's isotropic Young's modulus."""
    lam, eta = scene.material.lame
    return eta * (3 * lam + 2 * eta) / (lam + eta)


def transversely_isotropic(scene, **change) -> dict:
    """A transversely isotropic material as stiff as the scene's, with ``change``."""
    e = young(scene)
    table = {"law": "transversely_isotropic", "young_plane": 2 * e, "young_axis": e, "poisson_plane": 0.3,
             "poisson_axis": 0.2, "shear_axis": 0.4 * e}
    return {"material": {**table, **change}}


def compaction_energy(scene):
    """ψ of the compaction law with the scene's constants and β = 5λ + η (a Python function for material.energy)."""
    lam, eta = scene.material.lame
    beta = 5 * lam + eta
    return lambda e: eta * ngs.InnerProduct(e, e) + lam / 2 * ngs.Trace(e) ** 2 + beta / 2 * ngs.IfPos(
        ngs.Trace(e), 0, ngs.Trace(e) ** 2)


def plate_only(fn):
    return lambda s: fn(s) if s.loads.plate is not None else None


def heated(**change):
    """The strip heated (k = ρ = c = 1, η = 1) with ``change`` (the heat is read at solve time: one kind will do)."""
    base = {"heat.model": "conduction", "heat.partition": 1.0, "material.conductivity": 1.0, "material.density": 1.0,
            "material.heat_capacity": 1.0}
    return lambda s: {**base, **change} if s.geometry.kind == "strip" else None


def strip_only(fn):
    return lambda s: fn(s) if s.geometry.kind == "strip" else None


def programme(s, count=1, **keys) -> dict:
    """A programme of ``count`` stops filling the scene's time with its steps (``time.T``, ``time.steps`` kept)."""
    stops = [{"count": count, "duration": s.time.T / count}]
    return {"programme": {"stops": stops, "steps_per_stop": s.time.steps // count, **keys}}


def programme_file(s) -> Path:
    """The programme of :func:`programme` as a CSV file (beside the base scenes' part files)."""
    path = FOLDER["parts"] / "programme.csv"
    path.write_text(f"count,duration\n1,{s.time.T!r}\n")
    return path


FOLDER = {}


# key → the overrides that change it in a scene (None: not for that scene)
CHANGES = {
    "name": lambda s: {"name": "other"},
    "units": lambda s: {"units": None if s.units else "SI"},
    "geometry.kind": lambda s: {**geometry(s, kind="half_disk", size=[1.0], dirichlet=["top"]),
                                "loads.traction": {}, "loads.body_force": [0.0, -0.01], "mesh.maxh": 0.3}
    if s.geometry.kind == "strip" else None,
    "geometry.size": lambda s: None if s.geometry.size is None else {"geometry.size": [
        v * (1.0 if s.geometry.kind == "pad" and i == 2 else 1.05) for i, v in enumerate(s.geometry.size)]},
    "geometry.dirichlet": lambda s: {"geometry.dirichlet": [*s.geometry.dirichlet, free_boundary(s)]}
    if free_boundary(s) else None,
    "geometry.position": lambda s: {"geometry.position": [0.035, 0.002]} if s.geometry.kind == "pin" else None,
    "geometry.end": lambda s: geometry(s, end="flat", end_radius=None) if s.geometry.kind == "pin" else None,
    "geometry.end_radius": lambda s: {"geometry.end_radius": 1.2 * s.geometry.end_radius}
    if s.geometry.end == "sphere" else None,
    "geometry.backing": lambda s: {"geometry.backing": 0.25 * s.geometry.size[KINDS[s.geometry.kind].thickness]}
    if KINDS[s.geometry.kind].thickness is not None else None,
    "geometry.file": lambda s: {"geometry.file": str(copy_of(s.geometry.file))} if s.geometry.file else None,
    "mesh.maxh": lambda s: {"mesh.maxh": 0.9 * s.mesh.maxh} if s.mesh.maxh else None,
    "mesh.order": lambda s: {"mesh.order": 2},
    "mesh.contact_maxh": lambda s: {"mesh.contact_maxh": 0.5 * (s.mesh.contact_maxh or s.mesh.maxh)}
    if s.mesh.maxh else None,
    "mesh.contact_zone": lambda s: {"mesh.contact_zone": 0.2} if s.geometry.kind == "half_disk" else
    {"mesh.contact_zone": 0.002} if s.geometry.kind == "pin" else None,
    "mesh.zone_center": lambda s: {"mesh.zone_center": [0.05, 0.0]} if s.geometry.kind == "half_disk" else
    {"mesh.contact_zone": 0.002, "mesh.zone_center": [0.031, 0.0, 0.0]} if s.geometry.kind == "pin" else None,
    "mesh.grading": lambda s: {"mesh.grading": 0.5} if s.mesh.maxh else None,
    "mesh.max_elements": lambda s: {"mesh.max_elements": 1_000_000},
    "material.lame_lambda": lambda s: {"material.lame_lambda": 2.0} if s.material.lame_lambda is not None else None,
    "material.lame_mu": lambda s: {"material.lame_mu": 1.5} if s.material.lame_mu is not None else None,
    "material.regions": lambda s: {"material.regions": {"body": {"lame_mu": 2.0} if s.material.lame_mu else
                                                         {"young": 2 * s.material.young, "poisson": 0.2}}},
    "material.law": lambda s: {"material.law": "compaction", "material.compaction_modulus": 5 * young(s)},
    "material.compaction_modulus": lambda s: {"material.law": "compaction", "material.compaction_modulus": young(s)},
    "material.energy": lambda s: {"material": {"law": "energy", "energy": compaction_energy(s)}},
    "material.young_plane": lambda s: transversely_isotropic(s, young_plane=3 * young(s)),
    "material.young_axis": lambda s: transversely_isotropic(s, young_axis=0.5 * young(s)),
    "material.poisson_plane": lambda s: transversely_isotropic(s, poisson_plane=0.1),
    "material.poisson_axis": lambda s: transversely_isotropic(s, poisson_axis=0.1),
    "material.shear_axis": lambda s: transversely_isotropic(s, shear_axis=0.2 * young(s)),
    "material.axis": lambda s: transversely_isotropic(s, axis=[1.0] + [0.0] * (s.dim - 1)),
    "material.young": lambda s: {"material.young": 1.5 * s.material.young} if s.material.young else None,
    "material.poisson": lambda s: {"material.poisson": 0.1} if s.material.young else None,
    "contact.law": lambda s: {"contact.law": "power"},
    "contact.stiffness": lambda s: {"contact.stiffness": 1.5 * s.contact.stiffness},
    "contact.exponent": lambda s: {"contact.law": "power", "contact.exponent": 2.0},
    "contact.gap": lambda s: {"contact.gap": 0.8 * s.contact.gap},
    "contact.friction": lambda s: {"contact.friction": s.contact.friction + 0.1},
    "contact.wear": lambda s: {"contact.wear": 2 * s.contact.wear},
    "contact.wear_law": lambda s: {"contact.wear_law": "energy"},
    "contact.wear_exponents": lambda s: {"contact.wear_law": "power", "contact.wear_exponents": [1.5, 2.0]},
    "contact.direction": lambda s: {"contact.direction": [0.1, *s.contact.direction[1:]]},
    "foundation.velocity": lambda s: {"foundation.velocity": [0.5, *s.foundation.velocity[1:]]},
    "foundation.angular_velocity": lambda s: {"foundation.angular_velocity": 0.2 if s.dim == 2 else
                                              [0.0, 0.0, 1.2 * (s.foundation.angular_velocity or (0, 0, 5.0))[2]]},
    "foundation.center": lambda s: {"foundation.center": [0.001] * s.dim},
    "foundation.speed_table": lambda s: {"foundation.speed_table": [[0.0, 1.0], [s.time.T, 0.5]]},
    "loads.traction": lambda s: {"loads.traction": {b: scaled(v, 1.5) for b, v in s.loads.traction.items()}}
    if s.loads.traction else None,
    "loads.body_force": lambda s: {"loads.body_force": [0.0] * (s.dim - 1) + [-0.02 if s.loads.plate is None else -1e3]},
    "loads.time_table": lambda s: {"loads.time_table": [[0.0, 0.5], [s.time.T, 1.0]]},
    "loads.plate.boundary": plate_only(lambda s: {"loads.plate.boundary": free_boundary(s)}),
    "loads.plate.force": plate_only(lambda s: {"loads.plate.force": scaled(s.loads.plate.force, 1.2)}),
    "loads.plate.tilt": plate_only(lambda s: {"loads.plate.tilt": True}),
    "time.T": lambda s: {"time.T": 1.5 * s.time.T},
    "time.steps": lambda s: {"time.steps": STEPS + 1},
    "time.adaptive": lambda s: {"time.adaptive": True, "wear.integrator": "trapezoidal"},
    "time.tolerance": lambda s: {"time.adaptive": True, "time.tolerance": 1e-2, "wear.integrator": "trapezoidal"},
    "time.min_step": lambda s: {"time.adaptive": True, "time.min_step": 1e-3 * s.time.T,
                                "wear.integrator": "trapezoidal"},
    "time.max_step": lambda s: {"time.adaptive": True, "time.max_step": 0.5 * s.time.T,
                                "wear.integrator": "trapezoidal"},
    "wear.integrator": lambda s: {"wear.integrator": "implicit"},
    "wear.allow_unstable": lambda s: {"wear.allow_unstable": True},
    "solver.method": lambda s: {"solver.method": "full", "wear.integrator": "explicit", "wear.allow_unstable": True},
    "solver.tolerance": lambda s: {"solver.tolerance": 1e-9},
    "solver.max_iterations": lambda s: {"solver.max_iterations": 40},
    "output.every": lambda s: {"output.every": s.time.T / 3},   # T/2: the every of some bases
    "output.max_frames": lambda s: {"output.max_frames": 5_000},
    "output.times": lambda s: {"output.times": [0.0, s.time.T]},
    "output.checkpoint_seconds": lambda s: {"output.checkpoint_seconds": 0.0},
    "material.conductivity": heated(**{"material.conductivity": 2.0}),
    "material.heat_capacity": heated(**{"material.heat_capacity": 2.0}),
    "material.density": heated(**{"material.density": 2.0}),
    "material.expansion": heated(**{"material.expansion": 1e-3}),
    "foundation.temperature": heated(**{"foundation.temperature": 5.0}),
    "foundation.thermal_mass": heated(**{"foundation.thermal_mass": 2.0, "foundation.cooling": 0.5}),
    "foundation.cooling": heated(**{"foundation.thermal_mass": 2.0, "foundation.cooling": 1.5}),
    "foundation.conductivity": heated(**{"heat.partition": "effusivity", "foundation.conductivity": 2.0,
                                         "foundation.density": 1.0, "foundation.heat_capacity": 1.0}),
    "foundation.density": heated(**{"heat.partition": "effusivity", "foundation.conductivity": 1.0,
                                    "foundation.density": 2.0, "foundation.heat_capacity": 1.0}),
    "foundation.heat_capacity": heated(**{"heat.partition": "effusivity", "foundation.conductivity": 1.0,
                                          "foundation.density": 1.0, "foundation.heat_capacity": 2.0}),
    "heat.model": heated(),
    "heat.partition": heated(**{"heat.partition": 0.5}),
    "heat.convection": heated(**{"heat.convection": [{"boundary": "top", "coefficient": 2.0}]}),
    "heat.ambient": heated(**{"heat.ambient": 20.0}),
    "heat.initial": heated(**{"heat.initial": 30.0}),
    "heat.scheme": heated(**{"heat.scheme": "bounded"}),
    "heat.interface": heated(**{"heat.interface": "conductance", "heat.contact_conductance": 2.0}),
    "heat.contact_conductance": heated(**{"heat.interface": "conductance", "heat.contact_conductance": 5.0}),
    "material.max_temperature": heated(**{"material.max_temperature": 0.5}),
    "foundation.max_temperature": heated(**{"foundation.max_temperature": 0.5}),


    # a part's life: read by the time loop alone (a strip shows it; the time grid kept: T and the steps alike)
    "wear.geometry": strip_only(lambda s: {"wear.geometry": "surface"}),
    "wear.update": strip_only(lambda s: {"wear.update": 0.5}),
    "wear.limit": strip_only(lambda s: {"wear.limit": 0.5 * s.geometry.size[1]}),
    "programme.stops": strip_only(lambda s: programme(s)),
    "programme.file": strip_only(lambda s: {**programme(s), "programme.stops": [],
                                            "programme.file": str(programme_file(s))}),
    "programme.steps_per_stop": strip_only(lambda s: programme(s, count=STEPS, steps_per_stop=1)),
    "programme.jump": strip_only(lambda s: programme(s, jump=True)),
    "programme.jump_tolerance": strip_only(lambda s: programme(s, jump_tolerance=0.01)),
}


def test_every_declared_key_has_a_level_and_a_change():
    """A key added without its level (what it invalidates) or without an entry here fails."""
    keys = {name: level_of(info) for name, info in declared_keys()}
    assert set(keys) | {"name"} == set(CHANGES), "give every scene key a change in CHANGES"
    assert all(isinstance(level, Level) for level in keys.values())


LEVELS = {name: level_of(info) for name, info in declared_keys()}
PIECES = (("mesh", Level.MESH), ("body", Level.SPACE), ("elastic", Level.STIFFNESS),
          ("condensation", Level.DIRECTION), ("loads", Level.LOADS))
CHEAP = {"contact_dofs", "contact_regions"}   # what a Discretization reads when it is made (dense or matrix-free)


def base_scenes(folder: Path) -> dict:
    """The base scene of each kind, the part files in ``folder`` (mesh kind: the strip's mesh saved as a file)."""
    FOLDER["parts"] = folder
    for path in (folder / "cad_pad.step", copy_of(folder / "cad_pad.step")):   # geometry.file's change: same content
        shutil.copy(SHIPPED / "cad_pad.step", path)
    scenes = {}
    for kind, (name, overrides) in BASES.items():
        if kind == "step":
            overrides = {**overrides, "geometry.file": str(folder / "cad_pad.step")}
        scenes[kind] = ngwear.load_scene(SHIPPED / name).replace(**{**overrides, "time.steps": STEPS})
    path = folder / "strip.vol"
    build_mesh(scenes["strip"]).ngmesh.Save(str(path))
    shutil.copy(path, copy_of(path))
    scenes["mesh"] = scenes["strip"].replace(**{"geometry": {"kind": "mesh", "file": str(path), "dirichlet": ["left"]},
                                                "mesh": {"order": 1}})
    return scenes


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    return base_scenes(tmp_path_factory.mktemp("parts"))


@pytest.fixture(scope="module")
def meshes(scenes):
    """The mesh of each base scene (a discretization on it builds its pieces on first use)."""
    return {kind: build_mesh(scene) for kind, scene in scenes.items()}


@pytest.fixture(scope="module")
def base(scenes):
    """The base scene of each kind and a discretization that has run it (every piece built)."""
    cache = {}

    def get(kind):
        if kind not in cache:
            disc = Discretization(scenes[kind])
            assert ngwear.simulate(scenes[kind], discretization=disc, progress=False).completed
            cache[kind] = scenes[kind], disc
        return cache[kind]

    return get


def changed_keys(scene, changed) -> dict:
    """The declared keys whose values differ between the scenes, with their levels."""
    return {name: level for name, level in LEVELS.items() if changed.value(name) != scene.value(name)}


def expensive(disc: Discretization) -> dict:
    """The expensive members (cached properties but the cheap ones) that the discretization's pieces have built."""
    found = {}
    for piece in (disc, disc.body, disc.elastic, disc.condensation, disc.loads):
        names = [name for name, member in vars(type(piece)).items() if isinstance(member, cached_property)
                 and name not in CHEAP and name in vars(piece)]
        if names:
            found[type(piece).__name__] = names
    return found


def rebuilt(old: Discretization, new: Discretization) -> Level:
    """The first piece that ``new`` does not share with ``old``."""
    return next((level for name, level in PIECES if getattr(new, name) is not getattr(old, name)), Level.NOTHING)


def shares_below(old: Discretization, new: Discretization, level: Level) -> list[str]:
    """What is wrong with ``new`` sharing exactly the pieces of ``old`` below ``level`` (empty: nothing)."""
    wrong = [f"{name} {'kept' if getattr(new, name) is getattr(old, name) else 'rebuilt'}" for name, at in PIECES
             if (getattr(new, name) is getattr(old, name)) != (at < level)]
    wrong += [f"{name} of the old scene" for name in ("elastic", "condensation", "loads")
              if getattr(new, name) is not getattr(old, name) and getattr(new, name).scene is not new.scene]
    return wrong + (["contact kept"] if new.contact is old.contact or new.contact.scene is not new.scene else [])


@pytest.mark.parametrize("key", list(CHANGES))
def test_a_change_gives_its_declared_level_and_keeps_the_pieces_below(scenes, meshes, monkeypatch, key):
    """A change gives the least level declared by the keys it changes, and with_scene keeps the pieces below it.

    For every part kind the key applies to: the key is among those changed, Scene.changed_from gives the least of
    their declared levels and Discretization.reuse says so; with_scene shares exactly the pieces below that level,
    remeshes (build_mesh of the changed scene) at MESH only, and builds no expensive piece, nor lets the old build one.
    """
    meshed, old = [], {}

    def build(scene, *_, **__):     # with_scene remeshes through Discretization(scene): the old mesh under a new name
        meshed.append(scene)
        return ngs.Mesh(old["mesh"].ngmesh)
    monkeypatch.setattr(discrete, "build_mesh", build)
    wrong, applied = {}, []
    for kind, scene in scenes.items():
        overrides = CHANGES[key](scene)
        if overrides is None:
            continue
        applied.append(kind)
        disc = Discretization(scene, mesh=meshes[kind])      # nothing built yet
        old["mesh"], changed, meshed[:] = disc.mesh, scene.replace(**overrides), []
        keys = changed_keys(scene, changed)
        declared = changed.changed_from(scene)
        reuse = disc.reuse(changed)
        new = disc.with_scene(changed)
        problems = [*([] if key in keys else [f"{key} unchanged"]),
                    *([] if declared == min(keys.values(), default=Level.NOTHING) else [f"{declared!r} from {keys}"]),
                    *([] if reuse.rebuilt == declared else [f"reuse says {reuse}"]),
                    *shares_below(disc, new, declared),
                    *([] if meshed == ([changed] if declared is Level.MESH else []) else [f"meshed {len(meshed)}x"]),
                    *([] if declared is not Level.MESH or new.mesh is not disc.mesh else ["the old mesh"]),
                    *(f"built {found}" for found in filter(None, (expensive(new), expensive(disc))))]
        if problems:
            wrong[kind] = problems
    assert applied, f"{key}'s change applies to no part kind"
    assert not wrong, wrong


def contents(disc: Discretization, level: Level) -> dict:
    """What the pieces below ``level`` hold, built (without factorising): the data a run reads from them."""
    held = {}
    if level > Level.SPACE:
        held |= {"free": disc.body.free, "coords": disc.points.coords, "weights": disc.points.weights,
                 "P": disc.points.P.toarray()}
    if level > Level.STIFFNESS:
        u = 1e-3 * np.random.default_rng(0).standard_normal(disc.fes.ndof)
        held |= {"schur": disc.elastic.schur, "stiffness": disc.elastic.stiffness.toarray(),
                 "forces": disc.elastic.forces(u * disc.body.free)}
    if level > Level.DIRECTION:
        segments = disc.condensation.segments
        held |= {"nu": disc.condensation.nu, "N": disc.condensation.N.toarray(), "d0": disc.condensation.d0,
                 "plate_modes": disc.condensation.plate_modes, "lengths": segments.lengths,
                 "plate_normal": segments.plate_normal}
    if level > Level.LOADS:
        held |= {"load": disc.loads.load, "plate_force": disc.loads.plate_force}
    return held


@pytest.fixture(scope="module")
def assembled(scenes, meshes):
    """A discretization of each base scene whose pieces hold what :func:`contents` reads (built once)."""
    discs = {kind: Discretization(scene, mesh=meshes[kind]) for kind, scene in scenes.items()}
    for disc in discs.values():
        contents(disc, Level.NOTHING)
    return discs


@pytest.mark.parametrize("key", list(CHANGES))
def test_the_kept_pieces_hold_what_a_fresh_discretization_builds(scenes, meshes, assembled, key):
    """What the pieces that with_scene keeps hold equals what a discretization of the changed scene builds.

    Every key on every part kind, on the same mesh, bit for bit, nothing factorised: a key declared above a piece that
    reads it fails here, where the sampled runs below may not have it.
    """
    wrong = {}
    for kind, scene in scenes.items():
        overrides = CHANGES[key](scene)
        if overrides is None:
            continue
        changed = scene.replace(**overrides)
        level = changed.changed_from(scene)
        if level is Level.MESH:
            continue
        kept = contents(assembled[kind].with_scene(changed), level)
        fresh = contents(Discretization(changed, mesh=meshes[kind]), level)
        differ = [name for name in kept if not (kept[name] is None and fresh[name] is None
                                                or np.array_equal(kept[name], fresh[name]))]
        if differ:
            wrong[kind] = differ
    assert not wrong, wrong


# The end-to-end sample: a run on the reused discretization (every piece built by the base's run) equals a fresh run
# bit for bit.  Each level in 2D and 3D, and what a run reads beyond the pieces' contents above: the kind change, part
# files of the same content (a CAD file, a mesh file), the plate's boundary and tilt (a tilting pad; a tilting pin
# stops at step 0, the same step), a backing region, nonlinear laws (the kink, a Python energy), anisotropy, the
# compliance law, the full-system path (with a plate), adaptive steps, heat and thermal expansion, a geometry update
# (wear.geometry), a programme from a CSV file, jumps, a rotating disc, a speed table, units.
SAMPLE = [
    ("geometry.kind", "strip"), ("geometry.file", "mesh"), ("geometry.file", "step"),                     # MESH
    ("mesh.order", "strip"), ("geometry.dirichlet", "mesh"), ("loads.plate.boundary", "pad"),             # SPACE
    ("geometry.dirichlet", "step"),
    ("material.lame_mu", "strip"), ("material.law", "half_disk"), ("material.energy", "strip"),           # STIFFNESS
    ("material.regions", "pad"), ("material.axis", "box"),
    ("contact.direction", "strip"), ("contact.direction", "pad"), ("loads.plate.tilt", "pad"),            # DIRECTION
    ("loads.plate.tilt", "pin"),
    ("loads.traction", "strip"), ("loads.body_force", "half_disk"), ("loads.body_force", "pad"),          # LOADS
    ("loads.plate.force", "pin"),
    ("contact.friction", "half_disk"), ("contact.law", "half_disk"), ("contact.gap", "half_disk"),        # NOTHING
    ("contact.stiffness", "strip"), ("loads.time_table", "mesh"), ("solver.method", "strip"), ("solver.method", "pad"),
    ("time.adaptive", "strip"), ("heat.model", "strip"), ("material.expansion", "strip"),
    ("wear.geometry", "strip"), ("programme.file", "strip"), ("programme.jump", "strip"),
    ("contact.stiffness", "box"), ("foundation.angular_velocity", "pin"), ("foundation.speed_table", "pad"),
    ("loads.time_table", "step"), ("time.adaptive", "box"), ("mesh.max_elements", "step"), ("units", "pad"),
]


def test_the_sample_has_every_level_in_2d_and_3d(scenes):
    assert all(CHANGES[key](scenes[kind]) is not None for key, kind in SAMPLE), "a sampled change does not apply"
    levels = {(scenes[kind].replace(**CHANGES[key](scenes[kind])).changed_from(scenes[kind]), scenes[kind].dim)
              for key, kind in SAMPLE}
    assert levels == {(level, dim) for level in Level for dim in (2, 3)}


@pytest.mark.slow
@pytest.mark.parametrize("key, kind", SAMPLE, ids=[f"{k}-{kind}" for k, kind in SAMPLE])
def test_a_change_run_on_the_reused_discretization_equals_a_fresh_run(base, key, kind):
    scene, disc = base(kind)
    changed = scene.replace(**CHANGES[key](scene))
    declared = changed.changed_from(scene)
    reuse = disc.reuse(changed)
    new = disc.with_scene(changed)
    assert reuse.rebuilt == declared == rebuilt(disc, new), (str(reuse), declared)
    assert not shares_below(disc, new, declared)
    reused = ngwear.simulate(changed, discretization=new, progress=False)
    fresh = ngwear.simulate(changed, progress=False)
    assert reused.status == fresh.status           # completed, or stopped at the same step (a tilting pin)
    for name in ("times", "wear", "normal_displacement", "pressure", "reaction", "plate_displacement"):
        assert np.array_equal(getattr(reused, name), getattr(fresh, name)), name
    assert fresh.steps < 0 or np.array_equal(reused.displacement(-1), fresh.displacement(-1))


@pytest.mark.parametrize("change, level", [({"contact.friction": 0.3}, Level.NOTHING),
                                           ({"material.lame_mu": 2.0}, Level.STIFFNESS),
                                           ({"loads.traction": {"top": [0.0, -0.2]}}, Level.LOADS),
                                           ({"contact.direction": [0.1, -1.0]}, Level.DIRECTION),
                                           ({"mesh.order": 2}, Level.SPACE),
                                           ({"mesh.maxh": 0.4}, Level.MESH)])
def test_what_is_rebuilt_is_counted(paper_scene, change, level):
    """μ rebuilds nothing, a material the factorisation, the mesh size the mesh: the pieces say so by identity."""
    scene = paper_scene.replace(**{"mesh.maxh": 0.5, "time.steps": 3, "wear.integrator": "trapezoidal"})
    disc = Discretization(scene)
    ngwear.simulate(scene, discretization=disc, progress=False)
    new = ngwear.simulate(scene.replace(**change), discretization=disc, progress=False).discretization
    assert rebuilt(disc, new) == level == disc.reuse(scene.replace(**change)).rebuilt
    factorised = "operator" in vars(new.elastic) and new.elastic is not disc.elastic
    assert factorised == (level <= Level.STIFFNESS)


def test_reuse_says_what_is_kept(paper_scene):
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.5}))
    assert str(disc.reuse(disc.scene.replace(**{"contact.wear": 0.5}))) == "reuses everything"
    assert str(disc.reuse(disc.scene.replace(**{"material.lame_mu": 2.0}))) == \
        "rebuilds factorisation, contact compliance, loads; keeps mesh, space"


def test_zero_friction_matrix_is_symmetric(paper_scene):
    """μ = 0: the condensed Newton matrix is the symmetric H (no friction compliance is formed)."""
    disc = Discretization(paper_scene.replace(**{"mesh.maxh": 0.2}))
    H = disc.condensation.normal_compliance
    assert np.allclose(H, H.T, atol=1e-14 * np.abs(H).max())
    frictional = H + disc.condensation.friction_compliance(disc.contact.motion.n_star(1.0))
    assert not np.allclose(frictional, frictional.T, atol=1e-6 * np.abs(H).max())


def test_zero_wear_rate_gives_no_wear(paper_scene):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10, "contact.wear": 0.0})
    r = ngwear.simulate(scene, progress=False)
    assert r.wear.max() == 0 and r.pressure.max() > 0
    assert np.allclose(r.normal_displacement, r.normal_displacement[0], atol=1e-14), "steady without wear"


def test_zero_friction_skips_friction_work(paper_scene, monkeypatch):
    frictionless = Discretization(paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10, "contact.friction": 0.0}))

    def forbidden(*_):
        raise AssertionError("friction compliance formed although μ = 0")
    monkeypatch.setattr(frictionless.condensation, "friction_compliance", forbidden)
    assert ngwear.simulate(frictionless.scene, discretization=frictionless, progress=False).completed
