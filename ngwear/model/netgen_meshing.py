"""Netgen's meshing of a part: its size estimated before, and done where a stop ends it within a second.

Estimate (:func:`estimate`).  Netgen makes about c_d Ω / h^d elements of size h = ``mesh.maxh`` in a part of area
(2D) or volume (3D) Ω: c₂ = 2.3 triangles, c₃ = 5.5 tetrahedra (measured on strips, boxes and pads).  A face (an
edge in 2D) of measure M refined to h_f < h (``mesh.contact_maxh``) adds a layer in which the size grows away from
it at the rate γ = ``mesh.grading`` (measured: γ ≈ the grading), over the depth D = min((h − h_f)/γ, Ω/M):

    N ≈ c_d (Ω / h^d + Σ_f M ∫_0^D ((h_f + γ s)^(−d) − h^(−d)) ds).

Against Netgen on the shipped scenes and refined strips and boxes it is within a factor 2 (a pad two elements
thick, refined: 3 × under).  A scene whose estimate passes ``mesh.max_elements`` is refused before meshing
(:func:`check_size`), naming ``mesh.maxh`` (or ``mesh.contact_maxh`` when the refined layer makes most of it).

Where (:func:`generate`).  A mesh estimated above :data:`IN_PROCESS` elements is made in a child process
(:func:`ngwear.child.run`) that builds the part from the same keys (the same mesh as in this process) and writes the
mesh file: a set ``stop`` kills it at once (:class:`Stopped`), the end of this process within a second; it ignores
SIGINT (this process decides), and Netgen crashing there is an error here.  Netgen does not stop in this process:
its volume mesher ignores its own terminate flag for long stretches.  Smaller meshes, quick for Netgen, are made
here.

With a refined zone (:mod:`ngwear.model.zone`) Γ_C's faces carry no size of their own (:func:`part`): Netgen's
local size is held in the zone instead.  The estimate is made on the faces refined all over, an upper bound.
"""
from __future__ import annotations

import threading
from pathlib import Path

import netgen.meshing
from netgen.occ import OCCGeometry

from ..child import ChildError, ChildStopped, run
from . import zone
from .keys import SceneError
from .kinds import KINDS

DENSITY = {2: 2.3, 3: 5.5}
"""c_d: Netgen's elements per h^d of area (2D) or volume (3D) at mesh size h."""
IN_PROCESS = 10_000
"""Largest estimated mesh made in this process (soon done: a stop may wait for it); larger ones in a child that a stop
kills."""


class Stopped(RuntimeError):
    """A run stopped by its ``stop`` event before its first step; the message names the stage."""


def estimate(shape, dim: int, maxh: float, grading: float | None) -> tuple[float, float]:
    """(All elements, those of the refined layers) Netgen makes of ``shape`` (see the module docstring)."""
    gamma, density = grading if grading is not None else 0.3, DENSITY[dim]
    omega = sum(part.mass for part in (shape.solids if dim == 3 else shape.faces))
    refined = [(f.mass, f.maxh) for f in (shape.faces if dim == 3 else shape.edges) if f.maxh < maxh]
    layers = 0.0
    for measure, h in refined:
        depth = min((maxh - h) / gamma, omega / measure)
        top = h + gamma * depth
        layers += measure * ((h ** (1 - dim) - top ** (1 - dim)) / (gamma * (dim - 1)) - depth / maxh ** dim)
    return density * (omega / maxh ** dim + layers), density * layers


def check_size(scene, shape) -> None:
    """Refuse, before meshing, a part whose estimated elements pass ``mesh.max_elements``."""
    m = scene.mesh
    count, layers = estimate(shape, scene.dim, m.maxh, m.grading)
    if count > m.max_elements:
        name, value = ("mesh.contact_maxh", m.contact_maxh) if layers > count / 2 else ("mesh.maxh", m.maxh)
        raise SceneError(f"{name}: {value:g} gives about {count:.3g} elements, more than mesh.max_elements = "
                         f"{m.max_elements} (Netgen's memory and time grow with them); give a larger {name}, or "
                         "raise mesh.max_elements")


def part(geometry, mesh):
    """The part's shape as Netgen meshes it: with a refined zone, Γ_C's faces without a size of their own."""
    zoned = zone.radius(geometry, mesh) is not None
    return KINDS[geometry.kind].build(geometry, mesh.model_copy(update={"contact_maxh": None}) if zoned else mesh)


def generate(scene, shape, path: Path, stop: threading.Event | None = None) -> None:
    """Mesh ``shape`` (built from ``scene``, :func:`part`) and write it to ``path``: here, or in a child when large.

    Raises :class:`Stopped` when ``stop`` is set while a child meshes (the child is killed, ``path`` not written),
    SceneError when a refined zone holds no point of Γ_C, and what Netgen raises (in a child: a RuntimeError, one
    line, also when Netgen crashes).
    """
    g, m, direction = scene.geometry, scene.mesh, tuple(scene.contact.direction)
    if estimate(shape, g.dim, m.maxh, m.grading)[0] <= IN_PROCESS:
        _mesh(shape, g, m, direction).Save(str(path))
        return
    try:
        run(_generate, g, m, direction, str(path), stop=stop, quiet=True)
    except ChildStopped:
        raise Stopped("meshing (Netgen)") from None
    except ChildError as err:
        if isinstance(err.__cause__, SceneError):
            raise err.__cause__ from None
        raise RuntimeError(f"Netgen died of {err.signal} in its child process" if err.signal else str(err)) from None


def _mesh(shape, g, m, direction):
    """Netgen's mesh of ``shape`` at ``mesh.maxh`` (and ``mesh.grading``), held to ``mesh.contact_maxh`` in a zone."""
    options = {"grading": m.grading} if m.grading is not None else {}
    if zone.radius(g, m) is None:
        return OCCGeometry(shape, dim=g.dim).GenerateMesh(maxh=m.maxh, **options)
    parameters = netgen.meshing.MeshingParameters(maxh=m.maxh, **options)
    zone.restrict(parameters, shape, g, m, direction)
    return OCCGeometry(shape, dim=g.dim).GenerateMesh(parameters)


def _generate(geometry, mesh, direction, path: str) -> None:
    """:func:`generate` in its child: build the part from the keys, mesh it, write the mesh file."""
    from . import shapes, user_parts  # noqa: F401 - they register the kinds

    _mesh(part(geometry, mesh), geometry, mesh, direction).Save(path)
