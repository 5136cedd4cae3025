"""Transient heat conduction in the body, heated by friction on Γ_C (``docs/guide/heat.md``).

    ρc ∂T/∂t = ∇·(k ∇T) in Ω,   k ∂T/∂n = η q on Γ_C,   −k ∂T/∂n = h_b (T − T_∞) on the convected boundaries b,
    ∂T/∂n = 0 on every other boundary,   T(0) = T₀,

q = μ p ‖v*‖ the frictional power per unit area, η the body's share (:func:`ngwear.model.thermal.partition`),
ρc, k per region (:mod:`ngwear.model.thermal`).  P1 on the body's mesh, every region (the heat enters through
Γ_C and spreads smoothly; a temperature that is linear on each element is second order at the nodes, and the
contact points sit on its vertices or edge midpoints), backward Euler on the steps of the wear:

    (M + Δt (A + R)) T^{n+1} = M T^n + Δt (F^{n+1} + T_∞ r).

``heat.scheme = "consistent"``: M = ∫ ρc φ_i φ_j dx, A = K = ∫ k ∇φ_i·∇φ_j dx, R = Σ_b h_b ∫_b φ_i φ_j da (the most
accurate at the face; a node may fall below T₀ where a step is short against h²/κ, which :meth:`Heat.undershoot`
reports).  ``"bounded"``: the matrices of a discrete maximum principle, M = diag(∫ ρc φ_i dx) the lumped capacity,
R = diag(r), r_i = Σ_b h_b ∫_b φ_i da, and A = K + D with the couplings an obtuse element makes positive moved onto
the diagonal, D_ij = −max(K_ij, 0) (i ≠ j), D_ii = −Σ_{j≠i} D_ij (discrete upwinding).  Then M + Δt(A + R) is an
M-matrix with non-negative row sums, and for F ≥ 0 every T^{n+1}_i ≥ min(min_j T^n_j, T_∞); what it took from the
consistent step is added back as far as that bound allows (:class:`Antidiffusion`).  The frictional heat is what
the contact's nodal quadrature gives, F = Eᵀ (η m ∘ q^{n+1}), with the contact points' weights m_i and
E_ij = φ_j(x_i) (1 at a point's own vertex; ½ at both ends of the edge whose midpoint a P2 point is).  The surface
temperature at the points is E T.  Since 1ᵀ M = ∫ ρc φ_j dx and A 1 = 0 in either scheme,

    ∫ ρc (T^{n+1} − T^n) dx = Δt (η Σ_i m_i q_i^{n+1} − r·(T^{n+1} − T_∞)),

the energy balance, holds to the round-off of the solve (:meth:`Heat.balance`).  The matrix is factorised
(PARDISO) once per step size; the last :data:`FACTORS` sizes are kept (adaptive steps change it).  A geometry update
(``wear.geometry = "surface"``) moves the mesh: :meth:`Heat.moved` keeps T at the vertices, assembles the matrices
anew and counts the heat the shrinking capacity takes away in the balance.
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass

import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from ngsolve.fem import NODE_TYPE

from ..model.coefficients import at_points, state_of
from ..model.thermal import partition, region_properties
from .counterface_temperature import Lumped, counterface
from .pardiso import Pardiso
from .stiffness import assembled

FACTORS = 4
"""Factorisations kept, one per step size (the most recently used)."""
CONDUCTANCE = "heat.contact_conductance"
"""The key of h_c (a contact coefficient: a number, a field of x, or of the state p, T, v)."""
UNDERSHOOT = 0.01
"""How far below the lowest temperature it starts from or is cooled towards a node may fall, as a share of the spread
of temperatures above it, before a run says so."""


@dataclass(frozen=True)
class Balance:
    """The body's heat so far: ``stored`` = ``supplied`` + ``exchanged`` − ``convected`` − ``removed``.

    ``stored`` ∫ ρc (T − T₀) dx, ``supplied`` Σ Δt η Q, ``convected`` Σ Δt r·(T − T_∞), ``removed`` the heat of the
    material the geometry updates took away (:meth:`Heat.moved`; 0 in the layer mode), ``exchanged`` Σ Δt Σ_i g_i (T_f −
    T_i) what the counterface gave through the contact conductance.
    """

    stored: float
    supplied: float
    convected: float
    removed: float = 0.0
    exchanged: float = 0.0

    @property
    def residual(self) -> float:
        """The balance's defect, stored − (supplied + exchanged − convected − removed): zero to round-off."""
        return self.stored - (self.supplied + self.exchanged - self.convected - self.removed)


class Heat:
    """The temperature of the body on the scene's mesh, one step at a time (:meth:`advance`).

    Parameters
    ----------
    scene : Scene
        With ``heat.model = "conduction"``: k, ρ, c per region, ``heat.*``, the counterface's keys.
    mesh : ngsolve.Mesh
        The body's mesh (every region).
    points : ContactPoints
        The contact points x_i and their weights m_i (:func:`ngwear.numerics.points.contact_points`).

    Attributes
    ----------
    space : ngsolve.FESpace
        P1 on the mesh.
    temperature : numpy.ndarray
        T at the nodes (the space's DOFs), now.
    time : float
        The time of ``temperature`` (the sum of the steps so far).
    partition : float
        η, the body's share of the frictional heat.
    power : float
        Q = Σ_i m_i q_i, the frictional power of the last step (body and counterface).
    counterface : Given or Lumped
        The counterface's temperature (:mod:`ngwear.numerics.counterface_temperature`).
    """

    def __init__(self, scene, mesh: ngs.Mesh, points):
        if scene.heat.model != "conduction":
            raise ValueError(f"heat: the scene has no temperature (heat.model = {scene.heat.model!r})")
        self.scene, self.ambient, self.start = scene, scene.heat.ambient, scene.heat.start
        self._assemble(mesh, points)
        self.temperature = np.full(self.space.ndof, self.start)
        self.counterface = counterface(scene)
        self.time = self.power = self.supplied = self.convected = self.removed = self.exchanged = 0.0
        self.lowest = (self.start, 0.0)

    def _assemble(self, mesh: ngs.Mesh, points) -> None:
        """M, A, R, r, E and the contact points' weights on the mesh as it is; no factorisation yet."""
        props, heat = region_properties(self.scene), self.scene.heat
        self.space = ngs.H1(mesh, order=1)
        u, v = self.space.TnT()
        capacity = mesh.MaterialCF({name: p.capacity for name, p in props.items()})
        conductivity = mesh.MaterialCF({name: p.conductivity for name, p in props.items()})
        ones = np.ones(self.space.ndof)
        consistent = assembled(ngs.BilinearForm(capacity * u * v * ngs.dx, symmetric=True))
        conduction = assembled(ngs.BilinearForm(conductivity * ngs.grad(u) * ngs.grad(v) * ngs.dx, symmetric=True))
        exchange = sp.csr_matrix(consistent.shape)
        for entry in heat.convection:
            exchange = exchange + assembled(ngs.BilinearForm(entry.coefficient * u * v * ngs.ds(entry.boundary),
                                                             symmetric=True))
        self.capacity, self.exchange = consistent @ ones, exchange @ ones    # ∫ ρc φ_j dx, r = Σ_b h_b ∫_b φ_j da
        if heat.scheme == "consistent":
            self.mass, self.stiffness, self.convection, self.fluxes = consistent, conduction, exchange, None
        else:
            self.mass, self.convection = sp.diags(self.capacity).tocsr(), sp.diags(self.exchange).tocsr()
            self.stiffness = upwinded(conduction)
            self.fluxes = Antidiffusion.of(consistent, conduction, exchange)
        self.evaluation = _evaluation(self.space, points)
        self.weights = points.weights
        law = heat.contact_conductance if heat.interface == "conductance" else None
        self.conductance_of_state = law is not None and bool(state_of(law, CONDUCTANCE))
        self.conductance = None if law is None or self.conductance_of_state else at_points(law, CONDUCTANCE,
                                                                                          points.coords)
        touching = mesh.Boundaries("contact").Neighbours(ngs.VOL).Mask()
        self.partition = partition(self.scene, [name for i, name in enumerate(mesh.GetMaterials()) if touching[i]])
        self._spread = (self.evaluation.T @ sp.diags(self.partition * self.weights)).tocsr()     # Eᵀ diag(η m)
        self._surroundings = self.ambient * self.exchange                                        # T_∞ r
        self._factors: OrderedDict[float, Pardiso] = OrderedDict()

    def moved(self, mesh: ngs.Mesh, points) -> float:
        """The body's mesh moved (a geometry update, same vertices): T carried node by node, the matrices rebuilt.

        ``mesh`` and ``points`` are the moved body's.  T_j stays T_j at vertex j (a P1 DOF is a vertex): the material
        does not move, but the worn material near the face leaves with the heat it holds; the heat the body's
        capacity lost, (c − c')·(T − T₀) with c = M 1, goes to :attr:`removed` (the balance's ``removed``).  Returns it.
        """
        before = self.capacity
        self._assemble(mesh, points)
        lost = float((before - self.capacity) @ (self.temperature - self.start))
        self.removed += lost
        return lost

    def advance(self, dt: float, generated: np.ndarray, touching: np.ndarray | None = None) -> np.ndarray:
        """T at the end of a step of length ``dt`` (backward Euler), the counterface's too; returns T (nodal).

        ``generated``: q_i = μ_i p_i ‖v*_i‖ at the contact points at the step's end, the frictional power per unit
        area; the body takes η q_i, the counterface (1 − η) Σ_i m_i q_i.  ``touching``: the points in contact
        (``heat.interface = "conductance"``: the faces exchange h_c (T_f − T) there, implicitly in both).
        """
        q = np.asarray(generated, dtype=float)
        if q.shape != self.weights.shape:
            raise ValueError(f"heat: one frictional power per contact point ({len(self.weights)}) (got {q.shape})")
        self.power = float(self.weights @ q)
        share = (1 - self.partition) * self.power
        rhs = self.mass @ self.temperature + dt * (self._spread @ q + self._surroundings)
        gains = self._gains(touching)
        if gains is None:
            low, face = self._factor(dt).solve(rhs), None
        else:                                   # Eᵀ g T_f on the right: T = a + b T_f, T_f by the counterface
            factor, spread = self._factor(dt, gains), self.evaluation.T @ gains
            if isinstance(self.counterface, Lumped):
                a, b = factor.solve(rhs), factor.solve(dt * spread)
                face = self.counterface.exchange(dt, share, gains, self.evaluation @ a, self.evaluation @ b)
                low = a + b * face
            else:
                face = self.counterface.temperature(self.time + dt)
                low = factor.solve(rhs + dt * spread * face)
        self.temperature = low if self.fluxes is None else self.fluxes.corrected(low, self.temperature, dt,
                                                                                   self.capacity)
        self.time += dt
        if (coldest := float(self.temperature.min())) < self.lowest[0]:
            self.lowest = (coldest, self.time)
        self.supplied += dt * self.partition * self.power
        self.convected += dt * float(self.exchange @ (low - self.ambient))
        if gains is not None:
            self.exchanged += dt * float(gains @ (face - self.evaluation @ low))
        if gains is None or not isinstance(self.counterface, Lumped):
            self.counterface.advance(self.time, dt, share)
        return self.temperature

    def _gains(self, touching) -> np.ndarray | None:
        """g_i = m_i h_c,i at the points in contact (None: no exchange, ``partition`` or nothing touching).

        h_c at the points: fixed, or of the state, set before each step from the last one's (``conductance``).
        """
        if self.conductance is None or touching is None or not np.any(touching):
            return None
        return self.weights * self.conductance * np.asarray(touching, dtype=float)

    def _factor(self, dt: float, gains: np.ndarray | None = None) -> Pardiso:
        """The factorisation of M + Δt (A + R + H), H = Eᵀ diag(g) E (lumped, bounded), made on its first use."""
        key = (dt, None if gains is None else gains.tobytes())
        if key in self._factors:
            self._factors.move_to_end(key)
        else:
            if len(self._factors) == FACTORS:
                self._factors.popitem(last=False)
            matrix = self.stiffness + self.convection
            if gains is not None:
                touch = (self.evaluation.T @ sp.diags(gains) @ self.evaluation).tocsr()
                matrix = matrix + (touch if self.fluxes is None else sp.diags(np.asarray(touch.sum(axis=1)).ravel()))
            self._factors[key] = Pardiso(self.mass + dt * matrix)
        return self._factors[key]

    def surface_temperature(self) -> np.ndarray:
        """T(x_i) at the contact points, shape (n,)."""
        return self.evaluation @ self.temperature

    def max_temperature(self) -> float:
        """The body's highest temperature (a P1 field's is at a node)."""
        return float(self.temperature.max())

    @property
    def heat_flux(self) -> float:
        """η Q, the frictional power into the body over the last step."""
        return self.partition * self.power

    @property
    def floor(self) -> float:
        """The lowest temperature the body starts from or is cooled towards: T₀, and T_∞ where it convects."""
        return min(self.start, self.ambient) if self.exchange.any() else self.start

    def undershoot(self) -> tuple[float, float] | None:
        """(T, t) of the coldest node, if it fell below :attr:`floor` by more than :data:`UNDERSHOOT` of the spread.

        The spread: of the temperatures above the floor.  The consistent step may undershoot; the bounded one never.
        """
        coldest, when = self.lowest
        spread = max(float(self.temperature.max()), self.start) - self.floor
        return (coldest, when) if self.floor - coldest > UNDERSHOOT * spread else None

    def foundation_temperature(self) -> float:
        """T_f, the counterface's temperature now."""
        return self.counterface.temperature(self.time)

    def balance(self) -> Balance:
        """The body's heat so far: what it stores, what friction supplied, what convection took."""
        stored = float(self.capacity @ (self.temperature - self.start))
        return Balance(stored, self.supplied, self.convected, self.removed, self.exchanged)

    @property
    def state(self) -> dict[str, np.ndarray]:
        """What a checkpoint keeps: T, its counters and the counterface's state.

        The counters: time, Q, supplied, convected, removed, exchanged, the lowest T and its time.
        """
        return {"temperature": self.temperature.copy(),
                "heat": np.array([self.time, self.power, self.supplied, self.convected, self.removed, self.exchanged,
                                  *self.lowest]),
                "counterface": np.array(self.counterface.state, dtype=float)}

    def restore(self, state: dict[str, np.ndarray]) -> None:
        """Go on from a :attr:`state` (of a heat on the same mesh)."""
        self.temperature = np.array(state["temperature"], dtype=float)
        self.time, self.power, self.supplied, self.convected, self.removed, self.exchanged, *lowest = map(
            float, state["heat"])
        self.lowest = tuple(lowest)
        self.counterface.state = state["counterface"]


def upwinded(conduction: sp.csr_matrix) -> sp.csr_matrix:
    """K + D: the positive couplings of K moved onto its diagonal (D 1 = 0, so (K + D) 1 = K 1 = 0).

    K + D is symmetric, positive semidefinite (D is a graph Laplacian of the positive couplings) and has no positive
    entry off its diagonal.
    """
    off = sp.triu(conduction, k=1).tocoo()
    positive = off.data > 0
    rows, cols, values = off.row[positive], off.col[positive], off.data[positive]
    coupling = sp.coo_matrix((values, (rows, cols)), shape=conduction.shape)
    coupling = (coupling + coupling.T).tocsr()
    return (conduction - coupling + sp.diags(np.asarray(coupling.sum(axis=1)).ravel())).tocsr()


@dataclass(frozen=True)
class Antidiffusion:
    """What the low-order scheme took from the consistent one, as fluxes between the coupled nodes i < j.

    The consistent scheme M_C Ṫ + (K + R_C) T = … is the low-order one plus Σ_j f_ij in row i,

        f_ij = m_ij (Ṫ_i − Ṫ_j) + c_ij (T_i − T_j),   c_ij = max(K_ij, 0) + (R_C)_ij,   f_ji = −f_ij,

    (m_ij, K_ij, (R_C)_ij the off-diagonal entries).  :meth:`corrected` adds them back as far as the local bounds
    allow (linearised flux correction with Zalesak's limiter on the side that loses heat): T = T_L + Δt M⁻¹ Σ_j α_ij
    f_ij with f_ij of the low-order T_L and Ṫ_L = (T_L − T^n)/Δt, a flux down the gradient of T_L left out, and
    α_ij = α_ji ∈ [0, 1] the largest that keeps every T_i at or above the least of T_L and T^n at its node and its
    neighbours.  So no node falls below the lowest temperature it started from or is cooled towards, while a heated
    face's flash is not clipped (the consistent scheme's surface rise on a resolved half-space to 1e-3); the fluxes
    cancel in pairs: the heat is T_L's to round-off.
    """

    rows: np.ndarray
    cols: np.ndarray
    mass: np.ndarray
    coupling: np.ndarray
    neighbours: np.ndarray
    starts: np.ndarray

    @classmethod
    def of(cls, consistent: sp.csr_matrix, conduction: sp.csr_matrix, exchange: sp.csr_matrix) -> "Antidiffusion":
        """The couplings i < j of the consistent capacity, the positive conduction and the exchange."""
        mass, positive = sp.triu(consistent, k=1), sp.triu(conduction, k=1)
        positive = positive.multiply(positive > 0)
        both = (sp.triu(exchange, k=1) + positive).tocsr()
        pattern = (abs(mass) + abs(both)).tocoo()
        rows, cols = pattern.row, pattern.col
        adjacent = (pattern + pattern.T + sp.eye(consistent.shape[0])).tocsr()     # each node among its neighbours
        return cls(rows, cols, np.asarray(mass.tocsr()[rows, cols]).ravel(), np.asarray(both[rows, cols]).ravel(),
                   adjacent.indices, adjacent.indptr[:-1])

    def corrected(self, low: np.ndarray, before: np.ndarray, dt: float, capacity: np.ndarray) -> np.ndarray:
        """T_L with the fluxes added back within the bounds of T_L (``before``: T^n, ``capacity``: M's diagonal)."""
        i, j = self.rows, self.cols
        rate = (low - before) / dt
        flux = self.mass * (rate[i] - rate[j]) + self.coupling * (low[i] - low[j])     # into i, out of j
        flux[flux * (low[i] - low[j]) < 0] = 0.0                                       # a diffusive flux: left out
        n = len(low)
        bottom = np.minimum(low, before)
        lowest = np.minimum(bottom, np.minimum.reduceat(bottom[self.neighbours], self.starts))
        loss = np.bincount(i, np.minimum(flux, 0), n) + np.bincount(j, np.minimum(-flux, 0), n)
        room = capacity * (lowest - low) / dt                                          # <= 0
        down = np.where(loss < 0, np.minimum(1.0, room / np.where(loss < 0, loss, -1.0)), 1.0)
        limited = np.where(flux > 0, down[j], down[i]) * flux                          # the losing node's share
        return low + dt * (np.bincount(i, limited, n) - np.bincount(j, limited, n)) / capacity


def frictional_power(friction: np.ndarray, pressure: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """q_i = μ_i p_i ‖v*_i‖, the power per unit area friction turns into heat at the contact points."""
    return friction * pressure * speed


def _evaluation(space: ngs.FESpace, points) -> sp.csr_matrix:
    """E (n × ndof): E_ij = φ_j(x_i) of the P1 basis at the contact points (vertices, or P2's edge midpoints).

    A P1 space's DOF j is vertex j (NGSolve numbers an order-1 H1 space's DOFs by the vertices).
    """
    mesh = space.mesh
    assert space.ndof == mesh.nv, "a P1 space: one DOF per vertex"
    vertices, edges = np.asarray(points.vertices), np.asarray(points.edges)
    on_edge = np.flatnonzero(vertices < 0)
    ends = np.array([[v.nr for v in mesh[ngs.NodeId(NODE_TYPE.EDGE, int(edges[i]))].vertices] for i in on_edge],
                    dtype=int).reshape(-1, 2)
    at_vertex = np.flatnonzero(vertices >= 0)
    rows = np.concatenate([at_vertex, np.repeat(on_edge, 2)])
    cols = np.concatenate([vertices[at_vertex], ends.ravel()])
    vals = np.concatenate([np.ones(len(at_vertex)), np.full(2 * len(on_edge), 0.5)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(points.n, space.ndof))
