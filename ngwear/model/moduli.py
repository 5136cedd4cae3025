"""A law sampled at strains: its stress σ(ε) and Mandel tangent D(ε), and m_F, L_F estimated from them.

For a law without closed-form constants (:class:`~ngwear.model.materials.Energy`) the hypotheses H(F) are checked
where the run goes: m_F ≈ min λ_min(D(ε)) and L_F ≈ max |λ(D(ε))| over the strains sampled.  A law is anything with
``dim``, ``stress(ε)`` and ``tangent(ε)`` returning NGSolve CoefficientFunctions of a d × d strain.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from functools import lru_cache

import ngsolve as ngs
import numpy as np

from . import mandel

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Moduli:
    """m_F and L_F estimated from the tangent's eigenvalues at ``samples`` strains (an upper / a lower bound)."""

    monotonicity: float
    lipschitz: float
    samples: int

    @property
    def warning(self) -> str | None:
        """The line to show when m_F ≤ 0: the paper's theory (H(F), Theorem 1) no longer applies."""
        if self.monotonicity > 0:
            return None
        return (f"material: the law is not strongly monotone over the run's strains (m_F = {self.monotonicity:.6g} "
                f"<= 0 at {self.samples} points): H(F) fails and the paper's existence and uniqueness no longer apply")


def tangent_values(law, eps: ngs.CoefficientFunction, mesh: ngs.Mesh, order: int = 2,
                   definedon=ngs.VOL) -> np.ndarray:
    """The Mandel tangent D(ε(x)) at the points of an order-``order`` rule on every element, (n, m, m)."""
    types = (ngs.TRIG, ngs.QUAD) if mesh.dim == 2 else (ngs.TET, ngs.HEX, ngs.PRISM, ngs.PYRAMID)
    points = mesh.MapToAllElements({t: ngs.IntegrationRule(t, order) for t in types}, definedon)
    m = mandel.size(law.dim)
    return np.asarray(law.tangent(eps)(points)).reshape(-1, m, m)


def tangent_at(law, strains: np.ndarray) -> np.ndarray:
    """The Mandel tangent D(ε) at each of the (n, d, d) strains ``strains``, (n, m, m)."""
    m = mandel.size(law.dim)
    return _at_strains(law.tangent, law.dim, strains, (m, m))


def stress_at(law, strains: np.ndarray) -> np.ndarray:
    """The stress σ(ε) at each of the (n, d, d) strains ``strains``, (n, d, d)."""
    return _at_strains(law.stress, law.dim, strains, (law.dim, law.dim))


def _at_strains(of_strain, dim: int, strains: np.ndarray, shape: tuple) -> np.ndarray:
    """Values of the CoefficientFunction ``of_strain(ε)`` at given strains, one evaluation per strain.

    The strain is a matrix of ``Parameter`` s (a constant would be folded away before NGSolve differentiates).
    """
    entries = [ngs.Parameter(0.0) for _ in range(dim * dim)]
    cf = of_strain(ngs.CF(tuple(entries), dims=(dim, dim)))
    point = _reference_point(dim)
    out = np.empty((len(strains),) + shape)
    for n, eps in enumerate(np.asarray(strains, dtype=float)):
        for entry, value in zip(entries, eps.ravel()):
            entry.Set(value)
        out[n] = np.asarray(cf(point)).reshape(shape)
    return out


def estimate_moduli(tangents: np.ndarray) -> Moduli:
    """m_F ≈ min λ_min(D), L_F ≈ max |λ(D)| over sampled Mandel tangents (n, m, m).

    The samples come from :func:`tangent_values` (a strain field) or :func:`tangent_at` (given strains);
    :attr:`Moduli.warning` is logged when m_F ≤ 0.
    """
    eig = np.linalg.eigvalsh(0.5 * (tangents + np.swapaxes(tangents, 1, 2)))
    moduli = Moduli(float(eig[:, 0].min()), float(np.abs(eig).max()), len(tangents))
    if moduli.warning:
        log.warning(moduli.warning)
    return moduli


def _reference_point(dim: int):
    """A point inside a one-element mesh, to evaluate CoefficientFunctions that do not depend on x."""
    return _reference_mesh(dim)(*(0.25,) * dim)


@lru_cache(maxsize=2)
def _reference_mesh(dim: int) -> ngs.Mesh:
    """One triangle (2D) or tetrahedron (3D); cached, so the points it maps outlive no mesh."""
    from netgen.meshing import Element2D, Element3D, FaceDescriptor, MeshPoint, Pnt
    from netgen.meshing import Mesh as NetgenMesh

    mesh = NetgenMesh(dim=dim)
    nodes = [mesh.Add(MeshPoint(Pnt(*c))) for c in np.vstack([np.zeros(3), np.eye(3)[:dim]])]
    if dim == 2:
        mesh.Add(FaceDescriptor(surfnr=1, domin=1, bc=1))
        mesh.Add(Element2D(1, nodes))
    else:
        mesh.Add(Element3D(1, nodes))
    return ngs.Mesh(mesh)
