"""A discretization's body (the pieces of levels ``MESH`` and ``SPACE``): its mesh, space, clamping, contact points.

:class:`Lazy` is what every piece of a :class:`~ngwear.numerics.discrete.Discretization` is: its members built on
first use and kept (the elastic operator, :mod:`.elastic`; the condensation and the loads, :mod:`.condensation`).
"""
from __future__ import annotations

from functools import cached_property

import ngsolve as ngs
import numpy as np

from ..model.scene import Scene
from .forms import displacement_space
from .points import contact_points
from .stiffness import GradientBlocks
from .strain import outer_facets


class Lazy:
    """A piece whose members (``cached_property``) are built on first use and kept: :meth:`built` says which are."""

    def built(self, name: str) -> bool:
        """Whether the member ``name`` has been built (a cached_property keeps its value in the instance)."""
        return name in self.__dict__

    def kept(self, name: str):
        """The member ``name`` if it has been built, else None (without building it)."""
        return self.__dict__.get(name)


class Body(Lazy):
    """Mesh, displacement space (clamped on the Dirichlet and plate boundaries) and contact points.

    ``blocks``: gradient blocks kept from a body of the same elements, by region (see :class:`GradientBlocks`).
    ``like``: a body on the same mesh object, its vertices moved since (a geometry update): its space, clamping,
    outer facets and the blocks' patterns are kept (they hold the mesh's elements, not their coordinates).
    """

    def __init__(self, scene: Scene, mesh: ngs.Mesh, blocks: dict[str, dict] | None = None, like: Body | None = None):
        self.mesh, self._blocks, self._patterns = mesh, blocks, None
        if like is not None and like.mesh is mesh:
            self.fes, self.free = like.fes, like.free
            if like.built("gradient_blocks"):
                self._patterns = like.gradient_blocks.patterns
            if like.built("outer_facets"):
                self.outer_facets = like.outer_facets
        else:
            self.fes = displacement_space(mesh, scene)
            self.free = np.array(list(self.fes.FreeDofs()), dtype=bool)
        self.points = contact_points(self.fes, scene.dim, scene.mesh.order)

    @cached_property
    def gradient_blocks(self) -> GradientBlocks:
        """The scalar gradient matrices of each region: the stiffness of any linear laws by sparse sums."""
        return GradientBlocks(self.fes, self._blocks, self._patterns)

    @cached_property
    def outer_facets(self) -> np.ndarray:
        """The facets of the body's outer boundary (sorted vertex numbers; see :func:`~ngwear.numerics.strain.segments`)."""
        return outer_facets(self.mesh)

    @cached_property
    def contact_regions(self) -> tuple[str, ...]:
        """The regions (materials) whose elements carry Γ_C."""
        touching = self.mesh.Boundaries("contact").Neighbours(ngs.VOL).Mask()
        return tuple(name for i, name in enumerate(self.mesh.GetMaterials()) if touching[i])

    @cached_property
    def contact_dofs(self) -> np.ndarray:
        """The free DOFs the contact points see (sorted)."""
        dofs = np.unique(self.points.P.indices)
        return dofs[self.free[dofs]]

    def locate(self, points: np.ndarray, inward: np.ndarray, scale: float):
        """NGSolve mesh points of reference points in the body (Γ_C points are taken from the body side, −ν)."""
        points = np.asarray(points, dtype=float)
        mips = self.mesh(*points.T)
        outside = mips["nr"] < 0
        for nudge in (1e-8, 1e-6, 1e-4):
            if not outside.any():
                break
            again = self.mesh(*(points[outside] + nudge * scale * inward).T)
            found = again["nr"] >= 0
            idx = np.flatnonzero(outside)[found]
            mips[idx] = again[found]
            outside[idx] = False
        if outside.any():
            raise ValueError(f"points: {points[outside][0].tolist()} is not in the body")
        return mips

    def gridfunction(self, u: np.ndarray) -> ngs.GridFunction:
        gf = ngs.GridFunction(self.fes)
        gf.vec.FV().NumPy()[:] = u
        return gf

    def set_nodal(self, gf: ngs.GridFunction, values: np.ndarray) -> None:
        """A scalar GridFunction of the contact form's space with the given values at the contact points."""
        gf.vec.FV().NumPy()[:] = self.points.Q @ values
