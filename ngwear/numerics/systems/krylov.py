"""The condensed step problem matrix-free: products with the compliance remembered, Newton steps by recycled GCR."""
from __future__ import annotations

import numpy as np
import scipy.optimize as spo

from ..wear import PointLaw
from .condensed import CondensedSystem
from .newton import PlateRows


class KrylovSystem(CondensedSystem):
    """The condensed step problem, matrix-free: for contact surfaces too large for dense algebra.

    Products with H and A = H + μ F go through ``recycler.memory``
    (:class:`~ngwear.numerics.recycle.ComplianceMemory`: one back-substitution with K's factorisation
    for each input direction not seen before in the run); the Newton matrix M of
    :class:`CondensedSystem` is applied, never formed, and its systems are solved by GCR with
    recycling (:class:`~ngwear.numerics.recycle.Recycler`), the columns of active points scaled by
    their estimated stiffness 1/(m_i h_i), h_i ≤ H_ii (``compliance``), to an absolute residual of
    ``tolerance``/100 of the problem's length scale, so that Newton's merit test sees exact steps.  A body held by
    the plate alone first moves rigidly to its force balance (:meth:`start`).
    """

    def __init__(self, recycler, compliance, weights, s_load, d0, gap, law: PointLaw, tolerance: float,
                 plate: PlateRows | None = None):
        super().__init__(compliance, weights, s_load, d0, gap, law, plate, tolerance)
        self.recycler = recycler

    def response(self, directed, normal):
        return self.recycler.memory(directed, normal)

    def start(self, x, lam):
        """The warm start moved rigidly along ν to the plate's force balance, for a body held by the plate alone.

        The balance of the translation's row needs no product (the plate's rows see the contact forces directly):
        from rest it is the solution with the body rigid, the patch of a soft layer to a few points; from the last
        step, the wear increment's motion.  Towards the foundation the move stops where the first points reach it
        (u_ν = d₀ + g), and their reactions λ take the force the layer does not carry: Newton starts with them active
        instead of sweeping a step's worth of the plate's force over the whole face.
        """
        if self.plate is None or not self.floating:
            return x, lam
        slope = self.plate.normal[:, 0]
        rigid = np.concatenate([slope, np.eye(len(x) - self.n)[0]])
        value = self._plate_rows(x, lam)[0]
        if value == 0:
            return x, lam
        toward = 1.0 if value < 0 else -1.0                                 # the row increases along the move
        balance = lambda t: self._plate_rows(x + toward * t * rigid, lam)[0]  # noqa: E731
        reach = np.inf
        if toward > 0:
            ahead = slope > 0
            reach = np.min(-self.gap(x)[ahead] / slope[ahead], initial=np.inf)
            if reach <= 0:
                return x, lam
        near, far = 0.0, min(1e-3 * self.scale, reach)                     # bracketed by doubling, then Brent
        while np.sign(balance(far)) == np.sign(value):
            if far >= reach:                                                # points at the foundation carry the rest
                x = x + reach * rigid
                touching = (self.gap(x) >= -1e-12 * self.scale) & (slope > 0)
                lam = lam.copy()
                lam[touching] += -balance(reach) / (self.m[touching] * slope[touching]).sum()
                return x, lam
            if far > 1e30:
                return x, lam
            near, far = far, min(2 * far, reach)
        return x + toward * spo.brentq(balance, near, far, xtol=1e-15 * self.scale) * rigid, lam

    def _solve(self, active, dp, rhs, lam):
        n, m = self.n, self.m
        scaling = np.ones(len(rhs))
        scaling[:n][active] = self.c[active]
        weights = (m * dp * ~active, m * active.astype(float))
        image = lambda u, response: self._image(active, u, weights[0] * u[:n], weights[1] * u[:n], response)  # noqa: E731
        return self.recycler.solve(active.tobytes() + dp.tobytes(), weights, image, scaling, rhs, self.atol)
