"""Geometry updates (``wear.geometry = "surface"``): the worn face recedes into the body, the discretization follows."""
from __future__ import annotations

import ngsolve as ngs
import numpy as np

from ..numerics.recession import Recession, contact_height
from ..numerics.topology import coordinates


class Surface:
    """``wear.geometry = "surface"``: the body's contact face recedes by the wear; the discretization follows.

    After each recorded step: once the wear since the last update (the layer's w) reaches ``wear.update`` × h, h the
    height of the smallest element at Γ_C (:func:`~ngwear.numerics.recession.contact_height`) or the layer's g if
    smaller (at most half of it: a coarse mesh's layer never wears through between updates, where its wear would
    slow down towards g), the mesh of the regions
    that carry Γ_C moves by the accumulated wear along −ν (:class:`~ngwear.numerics.recession.Recession`: a vertex of
    Γ_C by the least wear of the points at it), the wear it realised at the points, W, leaves the layer (w −= W,
    w ≥ 0) and goes to ``Result.removed`` (``total_wear`` = w + ΣW), and the discretization is rebuilt on the moved
    mesh: everything a change of geometry invalidates (the space's element maps, K and its factorisation, the
    contact points' weights, d₀, the compliance, the loads, the plate), the contact's factors and the unmoved
    regions' stiffness blocks kept (:meth:`~ngwear.numerics.discrete.Discretization.moved`).  The step's row is
    rewritten with the new w (its pressure and displacements are those it was solved with: the update moves the
    wear from the layer into the geometry).  A move that would leave an element below the quality bound or inverted
    stops the run with :attr:`~ngwear.numerics.recession.Quality.reason` (the run keeps its steps).  A run's
    heat goes on on the moved body (:meth:`~ngwear.runs.heating.Heating.moved`: T carried node by node, the heat's
    matrices rebuilt).

    A checkpoint keeps :attr:`state` (X₀, W and the moved vertices, exact); a run resumed from it (``saved``, ``disc``
    on the moved mesh) rebuilds the extension on X₀ as the first update did, so it goes on to the bit.
    """

    def __init__(self, scene, disc, saved: dict | None = None):
        self.scene, self.disc = scene, disc
        self.recession = None                          # built on a copy of the mesh at the first update
        if saved:
            self.recession = Recession.resumed(disc.mesh, disc.points, disc.condensation.nu, self._held(),
                                               saved["surface_reference"], saved["surface_wear"])
        self.threshold = self._threshold(disc.mesh)

    def _held(self) -> tuple[str, ...]:
        """The boundaries held in place besides those not parallel to ν: the clamped ones and a plate's."""
        plate = self.scene.loads.plate
        return tuple(self.scene.geometry.dirichlet) + (() if plate is None else (plate.boundary,))

    @property
    def state(self) -> dict[str, np.ndarray]:
        """What a checkpoint keeps to go on across updates ({}: none yet).

        X₀, W at Γ_C's vertices, the vertices now and K's ordering (the first K's, which every update's factorisation
        takes: a resumed run takes it too).
        """
        if self.recession is None:
            return {}
        ordering = self.disc.elastic.factored_ordering
        return {"surface_reference": self.recession.extension.reference, "surface_wear": self.recession.wear,
                "surface_coordinates": coordinates(self.recession.mesh),
                **({} if ordering is None else {"surface_ordering": ordering})}

    def _threshold(self, mesh) -> float:
        """``wear.update`` × the smaller of h (the smallest element's height at Γ_C) and g: never through the layer."""
        return self.scene.wear.update * min(contact_height(mesh), self.scene.contact.gap)

    def due(self, wear: np.ndarray) -> bool:
        """Whether the wear since the last update reaches the threshold somewhere."""
        return float(wear.max(initial=0.0)) >= self.threshold

    def update(self, recording, wear: np.ndarray):
        """Move the mesh by ``wear`` (the last row's); the new discretization, or None with the run stopped.

        The record follows (:meth:`~ngwear.results.recording.Recording.moved`): the last row's w less the realised W.
        """
        result = recording.result
        disc = self.disc
        if self.recession is None:
            result.thickness                                   # measured on the mesh as built, before it moves
            mesh = ngs.Mesh(disc.mesh.ngmesh.Copy())          # the mesh as built may serve other runs
            self.recession = Recession(mesh, disc.points, disc.condensation.nu, self._held())
        result.recession = self.recession                  # the record makes its other bodies' meshes with it
        coords, quality = self.recession.trial(wear)
        if not quality.acceptable:
            result.status = (f"step {result.steps} (t = {result.times[-1]:.4g}): wear.geometry = 'surface': "
                             f"{quality.reason}; the run stops there (a worn body is not remeshed within a run)")
            return None
        before = coordinates(self.recession.mesh)         # the mesh in force until now: frames may show it
        realised = self.recession.accept(coords, wear)
        self.disc = disc.moved(self.recession.mesh, self.recession.extension.regions)
        self.threshold = self._threshold(self.recession.mesh)
        recording.moved(realised, self.disc, before)
        return self.disc
