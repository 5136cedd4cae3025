"""The elasticity law's protocol and the registry of ``material.law`` (:class:`Law`, :func:`register`, :data:`LAWS`).

The laws themselves are the package's modules (:mod:`ngwear.model.materials`), each registering its own.
"""
from __future__ import annotations

from typing import ClassVar

import ngsolve as ngs

from ..keys import Constant

LAWS: dict[str, type[Law]] = {}
"""The laws a scene names (``material.law``), in the order of registration: the order of the documentation."""


def strain(u) -> ngs.CoefficientFunction:
    """ε(u) = (∇u + ∇uᵀ)/2."""
    return ngs.Sym(ngs.Grad(u))


class Law:
    """A material law: its declaration (class attributes) and what the numerics need of it (the protocol).

    Declaration: ``name`` (``material.law``; None for a law the scene does not name), ``doc`` (its line in the
    reference), ``ways`` (the parametrisations: tuples of constants, one of them given whole), ``optional`` (the
    constants it may also take), ``defaults`` (the constants a ``[material]`` that gives none gets; the default law's
    only) and :meth:`of` (the law of a checked table).

    Protocol: ``dim``; ``stress(ε)`` σ, ``energy(ε)`` ψ and ``tangent(ε)`` D in Mandel notation (m × m), NGSolve
    CoefficientFunctions of a d × d strain ε; ``elastic_integrand(u, v)`` = σ(ε(u)) : ε(v) (with u a TrialFunction,
    the bilinear form of a linear law, or the residual of a nonlinear one: NGSolve's ``Apply`` and
    ``AssembleLinearization`` evaluate and linearise it); ``tangent_integrand(ε, u, v)`` = D(ε) ε(u) : ε(v);
    ``tangent_at_zero()`` the linear law a fixed stiffness K₀ is built from; ``is_linear`` (then ``matrix``, its
    Mandel stiffness); ``monotonicity`` m_F and ``lipschitz`` L_F in closed form, or ``estimated``: they have none and
    :mod:`ngwear.model.moduli` samples them where the run goes; ``kinked``: ψ = ψ_lin + β/2 min(tr ε, 0)², with
    ``beta`` and ``linear_part()`` (the law of ψ_lin), which :mod:`ngwear.numerics.kink` turns into sparse algebra;
    ``out_of_plane(ε)`` σ₃₃ of a 2D (plane strain) law, None where the law does not define it (a ψ of the in-plane
    strain alone).
    """

    name: ClassVar[str | None] = None
    doc: ClassVar[str] = ""
    ways: ClassVar[tuple[tuple[Constant, ...], ...]] = ()
    optional: ClassVar[tuple[Constant, ...]] = ()
    defaults: ClassVar[dict[str, float]] = {}
    is_linear: ClassVar[bool] = False
    estimated: ClassVar[bool] = False
    kinked: ClassVar[bool] = False

    @classmethod
    def of(cls, table, dim: int, direction, key: str) -> Law:
        """The law of a ``[material]`` table whose constants fit it (``direction``: ν, a default axis)."""
        raise NotImplementedError

    @classmethod
    def check(cls, table, dim: int, direction, key: str) -> None:
        """Refuse constants that make no law (not positive definite): a SceneError naming the key."""
        cls.of(table, dim, direction, key)

    def out_of_plane(self, eps) -> ngs.CoefficientFunction | None:
        """σ₃₃ = (F(ε))₃₃ of a 2D law under plane strain at the in-plane strain ε; None: not defined by the law."""
        return None

    @classmethod
    def constants(cls) -> tuple[Constant, ...]:
        """Every constant the law takes, each once, in the order of its ways."""
        return tuple(dict.fromkeys(c for way in cls.ways for c in (*way, *cls.optional)))


def register(law: type[Law]) -> type[Law]:
    """Add a law to :data:`LAWS` under its ``name`` (a class decorator)."""
    LAWS[law.name] = law
    return law
