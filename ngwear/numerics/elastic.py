"""A discretization's elastic operator (the piece of level ``STIFFNESS``): the laws, K and its factorisation.

K is the laws' tangent at ε = 0 (K₀), or a nonlinear law's tangent at a state; factorised with the Schur complement
on the contact DOFs for the dense contact solve, or plainly (:mod:`ngwear.numerics.operators`).
"""
from __future__ import annotations

from functools import cached_property

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp

from ..model.materials import region_laws
from ..model.scene import Scene
from .body import Body, Lazy
from .forms import elastic_integrand, tangent_form
from .kink import Kink, kinked
from .operators import ElasticOperator, UpdatedOperator
from .stiffness import assembled

LOW_RANK = 32
"""Most kink points whose branch a tangent may change against a factorised K before it is factorised itself."""



class Elastic(Lazy):
    """The laws of the body's regions, a stiffness K and its factorisation.

    K is the laws' tangent at ε = 0 (K₀: for linear laws the stiffness), or with ``state`` their tangent at that
    displacement (the Newton iterate of a nonlinear law's step solver).  ``schur``: factorise with the
    Schur complement on the contact DOFs (the dense contact solve).  A tangent follows the operator ``base``; when it
    is an update of ``base``'s factorisation, ``columns`` caches that factorisation's K⁻¹Dᵀ (default: ``base``'s).
    ``ordering``: the fill-in reducing ordering K is factorised with (an earlier K's on the same elements, see
    :class:`~ngwear.numerics.operators.ElasticOperator`; None: METIS's).
    """

    def __init__(self, scene: Scene, body: Body, schur: bool, state: np.ndarray | None = None,
                 base: Elastic | None = None, columns: dict | None = None, ordering: np.ndarray | None = None):
        self.scene, self.body, self.schur, self.state, self.ordering = scene, body, schur, state, ordering
        self.laws = region_laws(scene)
        self.linear = all(law.is_linear for law in self.laws.values())   # K₀ is the stiffness: a step, one solve
        self.root, self.columns = self, {}  # the Elastic whose factorisation K's operator is; its K⁻¹Dᵀ by point
        self.changed = np.zeros(0, dtype=int)   # the kink points whose branch differs from the root's
        if base is not None:                # a tangent shares K_lin and the kink of the operator it follows
            for name in ("kink", "linear_stiffness"):
                if base.built(name):
                    setattr(self, name, getattr(base, name))
            changed = None if self.kink is None else np.flatnonzero(self.branches != base.root.branches)
            if changed is not None and len(changed) <= LOW_RANK:
                self.root, self.columns = base.root, base.columns if columns is None else columns
                self.changed = changed

    @cached_property
    def kink(self) -> Kink | None:
        """The compaction laws' kink as sparse algebra (:mod:`ngwear.numerics.kink`), where it is exact; else None."""
        return Kink(self.body.fes, self.laws) if kinked(self.body.fes, self.laws) else None

    @cached_property
    def linear_stiffness(self) -> sp.csr_matrix:
        """K_lin, the stiffness of the laws' linear parts (with :attr:`kink`: F(u) = K_lin u + kink forces)."""
        return self.body.gradient_blocks.stiffness({region: law if law.is_linear else law.linear_part()
                                                    for region, law in self.laws.items()})

    @cached_property
    def stiffness(self) -> sp.csr_matrix:
        """K: K₀ (the laws' tangent at ε = 0), or their tangent at ``state``; K_lin + the kink's tangent with a kink."""
        if self.root is not self:                                   # the root's K and the kink's rows that changed
            return (self.root.stiffness + self.kink.tangent(self._change, self.changed)).tocsr()
        if self.kink is not None:
            return (self.linear_stiffness + self.kink.tangent(self.branches)).tocsr()
        if self.state is None:
            return self.body.gradient_blocks.stiffness({r: law.tangent_at_zero() for r, law in self.laws.items()})
        return assembled(tangent_form(self.body.fes, self.laws, self.body.gridfunction(self.state)))

    @cached_property
    def branches(self) -> np.ndarray | None:
        """The kink's branches K is the tangent on (K₀: every point compressed); None without a kink."""
        if self.kink is None:
            return None
        return np.ones(len(self.kink.c), bool) if self.state is None else self.kink.compressed(self.state)

    def flips(self, u: np.ndarray) -> int | None:
        """The kink's points whose branch at u is not K's (K is F'(u) when 0); None without a kink."""
        return None if self.kink is None else int(np.count_nonzero(self.kink.compressed(u) != self.branches))

    def forces(self, u: np.ndarray) -> np.ndarray:
        """F(u), the internal forces Σ_r ∫_r σ_r(ε(u)) : ε(v) dx (for a linear body K u)."""
        if self.linear:
            return self.stiffness @ u
        if self.kink is not None:
            return self.linear_stiffness @ u + self.kink.forces(u)
        return self._apply(u)

    @cached_property
    def _apply(self):
        """F(u) by NGSolve's ``Apply`` of the symbolic form (any law)."""
        form = ngs.BilinearForm(elastic_integrand(self.body.fes, self.laws))
        u, out = ngs.GridFunction(self.body.fes), ngs.GridFunction(self.body.fes)

        def apply(values: np.ndarray) -> np.ndarray:
            u.vec.FV().NumPy()[:] = values
            form.Apply(u.vec, out.vec)
            return out.vec.FV().NumPy().copy()
        return apply

    @cached_property
    def operator(self) -> ElasticOperator | UpdatedOperator:
        """K's factorisation; for the dense contact solve with the Schur complement on the contact DOFs.

        A kinked law's tangent within :data:`LOW_RANK` branches of a factorised K (its :attr:`root`) is that
        factorisation's update by the kink's rows on those points (:class:`UpdatedOperator`), δ_q = ±c_q.
        """
        root, changed = self.root, self.changed
        if root is self:
            return ElasticOperator(self.stiffness, self.body.free, self.body.contact_dofs, schur=self.schur,
                                   ordering=self.ordering)
        if not len(changed):
            return root.operator
        return UpdatedOperator(root.operator, self.kink.D[changed], self.kink.c[changed] * self._change, self.columns,
                               changed)

    @property
    def factored_ordering(self) -> np.ndarray | None:
        """The ordering K's factorisation took (None before it is built, and with the Schur complement)."""
        operator = self.root.kept("operator")
        return None if operator is None else operator.ordering

    @property
    def _change(self) -> np.ndarray:
        """+1 where a changed point is compressed (the root's K released it), −1 where it is released."""
        return self.branches[self.changed].astype(float) - self.root.branches[self.changed]
