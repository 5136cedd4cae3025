"""The contact face of a frame for ParaView: a surface VTU of Γ_C with the contact fields at its points.

Its points are the contact points x_i in the order of ``result.npz``'s ``contact_points`` (so point i holds
``pressure[step, i]``, …), then, for P2 in 3D, where the vertices of Γ_C are no contact points (the edge-midpoint
rule), those vertices, with values reconstructed linearly from the midpoints as the frames' ``wear``
(:attr:`~ngwear.numerics.points.ContactPoints.at_vertices`).  Its cells are the facets of Γ_C: segments (2D) or
triangles (3D), quadratic ones for P2 (the midpoints their middle nodes), in the reference configuration: the mesh
as it is, or (:meth:`Surface.on`) as a geometry update left it (``wear.geometry = "surface"``: the frame's face).  Its
point fields are :data:`CONTACT_FIELDS`; a new one is one :class:`ContactField` there.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

CELL_TYPES = {(2, 1): 3, (2, 2): 21, (3, 1): 5, (3, 2): 22, (4, 1): 9, (4, 2): 23}
"""VTK cell types by (corners, order): line, quadratic edge, triangle, quadratic triangle, quad, quadratic quad."""


@dataclass(frozen=True)
class ContactField:
    """One point field of the contact file: its name, quantity (:mod:`ngwear.results.units`), meaning and values.

    ``values(result, step)``: an array (n,) or (n, d) at the contact points, the step's own (what it was solved with),
    written with ``components`` (a vector padded to 3); ``heat``: only in runs with a temperature.
    """

    name: str
    quantity: str | None
    doc: str
    values: Callable
    heat: bool = False
    components: int = 1


def _displacement(result, step):
    points = result.discretization.points
    return (points.P @ result.displacement(step)).reshape(points.n, -1)


def _slip_rate(result, step):
    return result.motion.speeds(result.speed_factor[step])


def _coefficient(row: str, fixed: str):
    """A contact coefficient of the step: its row (a coefficient of the state), else the run's fixed field."""
    def values(result, step):
        return result.rows[row][step] if row in result.rows else getattr(result, fixed)
    return values


CONTACT_FIELDS = (
    ContactField("displacement", "length", "u (for ParaView's Warp By Vector, as the frame's)", _displacement,
                 components=3),
    ContactField("pressure", "pressure", "p, the compliance's pressure", lambda r, j: r.pressure[j]),
    ContactField("reaction", "pressure", "λ, the rigid reaction where u_ν − d₀ = g", lambda r, j: r.reaction[j]),
    ContactField("wear", "length", "w, the layer's wear (since the last geometry update in `\"surface\"` runs)",
                 lambda r, j: r.wear[j]),
    ContactField("total_wear", "length", "all the material removed: w and what the geometry updates moved into the "
                                         "body", lambda r, j: r.total_wear_at(j)),
    ContactField("remaining_thickness", "length", "the worn region's thickness left under the point",
                 lambda r, j: r.remaining_thickness_of(r.total_wear_at(j))),
    ContactField("slip_rate", "velocity", "‖v*‖, the foundation's slip speed at the step (its speed factor s_v)",
                 _slip_rate),
    ContactField("friction", None, "μ of the step (`contact.friction`, at the last step's state where it depends on "
                                   "it)", _coefficient("step_friction", "friction_coefficient")),
    ContactField("wear_coefficient", "wear coefficient", "κ of the step (`contact.wear`, as μ)",
                 _coefficient("step_wear_coefficient", "wear_coefficient")),
    ContactField("temperature", "temperature", "T at the contact point at the step's end (`heat`)",
                 lambda r, j: r.surface_temperature[j], heat=True),
)
"""The contact file's point fields, in its order."""


@dataclass(frozen=True)
class Surface:
    """Γ_C as cells: ``points`` (m, 3), ``cells`` {VTK type: (k, nodes)}, ``extend`` (m − n) × n, ``ends`` (m, 2).

    ``extend`` gives the values at the added vertices from those at the contact points; ``ends`` the mesh vertices
    whose midpoint each point is (a vertex twice).
    """

    points: np.ndarray
    cells: dict[int, np.ndarray]
    extend: sp.csr_matrix
    ends: np.ndarray

    def values(self, at_points: np.ndarray) -> np.ndarray:
        """A field at the m points of the file from its values at the n contact points."""
        return np.concatenate([at_points, self.extend @ at_points])

    def on(self, coords: np.ndarray) -> Surface:
        """The face with its points where the mesh's vertices are at ``coords`` (nv × d): ½ (x_a + x_b) of the ends."""
        points = 0.5 * (coords[self.ends[:, 0]] + coords[self.ends[:, 1]])
        return replace(self, points=np.pad(points, ((0, 0), (0, 3 - points.shape[1]))))


def surface(disc) -> Surface:
    """The cells of Γ_C on the contact points (and, P2 in 3D, its vertices)."""
    mesh, points, order = disc.mesh, disc.points, disc.scene.mesh.order
    at_vertex = {int(v): i for i, v in enumerate(points.vertices) if v >= 0}
    at_edge = {int(e): i for i, e in enumerate(points.edges) if e >= 0}
    added: list[int] = []
    cells: dict[int, list] = {}
    edge_ends: dict[int, tuple[int, int]] = {}
    for el in mesh.Elements(ngs.BND):
        if el.mat != "contact":
            continue
        corners = [v.nr for v in el.vertices]
        for v in corners:
            if v not in at_vertex:
                at_vertex[v] = points.n + len(added)
                added.append(v)
        nodes = [at_vertex[v] for v in corners]
        if order == 2:
            edge_ends.update({e.nr: tuple(v.nr for v in mesh[e].vertices) for e in el.edges})
            edges = {frozenset(edge_ends[e.nr]): e.nr for e in el.edges}
            sides = [(corners[k], corners[(k + 1) % len(corners)]) for k in range(len(corners) if len(corners) > 2
                                                                                    else 1)]
            nodes += [at_edge[edges[frozenset(side)]] for side in sides]
        cells.setdefault(CELL_TYPES[len(corners), order], []).append(nodes)
    ends = [(v, v) if v >= 0 else edge_ends[e] for v, e in zip(points.vertices, points.edges)]
    coords = np.concatenate([points.coords, mesh.ngmesh.Coordinates()[added, :points.coords.shape[1]]])
    return Surface(np.pad(coords, ((0, 0), (0, 3 - coords.shape[1]))),
                   {kind: np.array(nodes) for kind, nodes in cells.items()}, points.at_vertices[added],
                   np.array(ends + [(v, v) for v in added], dtype=int).reshape(-1, 2))


def write_contact(result, step: int, face: Surface, path: Path) -> None:
    """Write the contact file of ``step`` to ``path`` (a ``.vtu``)."""
    import pyvista as pv

    grid = pv.UnstructuredGrid(face.cells, face.points)
    heated = result.scene.heat.model != "none"
    for field in (f for f in CONTACT_FIELDS if heated or not f.heat):
        values = face.values(np.asarray(field.values(result, step), dtype=float))
        grid.point_data[field.name] = np.pad(values, ((0, 0), (0, 3 - values.shape[1]))) if values.ndim == 2 else values
    grid.save(path)
