"""Compliance products remembered across a run, and the Newton systems solved in their span.

The matrix-free contact solve needs products R(a, b) = A a + H b, the normal displacements of the
contact points under the point forces a_i (ν + μ n*_i) + b_i ν, each one back-substitution with K's
factorisation.  A and H do not change during a run (while n* keeps its direction), and the inputs of
consecutive products are mostly combinations of earlier ones: for a piecewise-linear law the residual
after a Newton step is the residual before it plus the step's image, and consecutive steps' systems
differ by slowly varying data.  So a product is paid only for what is new:

* :class:`ComplianceMemory` keeps an orthonormal basis Y of all inputs so far and Z = R Y.  A request
  y = Y c + e costs a back-substitution only when ‖e‖ > η ‖y‖ (η = ``NEW``), and then only for e:
  R y = Z c + R e, exact to round-off.  When full, the oldest half is dropped.
* :class:`Recycler` solves the Newton systems M z = b, M = M(pattern) the matrix of
  :class:`~ngwear.numerics.systems.krylov.KrylovSystem` for one pattern (active set, support of p'), by GCR
  with recycling: every remembered input that the pattern can produce is a direction u with a known
  image M u (no product), so b is first solved by least squares in their span; then GCR directions
  u = S r (S the column scaling, r the residual, ⟂ the images so far) are added, one product each,
  until ‖r‖ ≤ atol; where S r falls in the span already (GCR's breakdown, M not positive real) the next
  direction is the last image (a Krylov step).  Directions are kept orthonormal and their images as
  M S Ũ = Q T (Q orthonormal), so the least-squares problems are as well conditioned as M S.
  The spans of the last patterns are kept (:class:`Span`, ``SPANS``, within ``BYTES``): a braking stop's steps
  cycle through a few patterns (p' follows the speed), and a pattern met again recalls only the inputs remembered
  since.
"""
from __future__ import annotations

import logging
from collections import OrderedDict

import numpy as np
import scipy.linalg as sla

log = logging.getLogger(__name__)

NEW = 1e-12
"""Relative size of the part of a requested input outside the remembered span below which no product is made."""
DEPENDENT = 1e-8
"""Relative size of a new direction's part outside the span of the earlier ones below which it is not taken."""
RECALLED = 1e-3
"""The same for a block of remembered directions, whose images are combined, not computed: their round-off grows
like the inverse of this (a smaller bound leaves residuals far above atol where p' varies over decades)."""
BYTES = 4e8
"""Memory budget of the remembered inputs and images, and that of the kept spans."""
SPANS = 8
"""Most patterns whose spans are kept (a stop to rest of the life pad, matrix-free at 46k DOFs, cycles through 5)."""


class ComplianceMemory:
    """R(a, b) = A a + H b through ``respond``, remembering an orthonormal basis of the inputs and their images."""

    def __init__(self, respond, n: int, capacity: int | None = None):
        self._respond, self.n = respond, n
        self.capacity = capacity or int(np.clip(BYTES / (8 * 6 * n), 16, 512))
        self.inputs = np.empty((2 * n, self.capacity))     # Y, orthonormal columns
        self.images = np.empty((n, self.capacity))         # Z = R Y
        self.size = 0
        self.products = 0
        self.generation = 0                                 # counts the times columns were dropped

    def __call__(self, directed: np.ndarray, normal: np.ndarray) -> np.ndarray:
        y = np.concatenate([directed, normal])
        norm = np.linalg.norm(y)
        if norm == 0.0:
            return np.zeros(self.n)
        Y = self.inputs[:, :self.size]
        c = Y.T @ y
        e = y - Y @ c
        again = Y.T @ e
        e -= Y @ again
        c += again
        out = self.images[:, :self.size] @ c
        rest = np.linalg.norm(e)
        if rest > NEW * norm:
            q = e / rest
            image = self._respond(q[:self.n], q[self.n:])
            self.products += 1
            self._append(q, image)
            out += rest * image
        return out

    def _append(self, q: np.ndarray, image: np.ndarray) -> None:
        if self.size == self.capacity:
            keep = self.capacity // 2
            self.inputs[:, :keep] = self.inputs[:, self.size - keep:self.size]
            self.images[:, :keep] = self.images[:, self.size - keep:self.size]
            self.size, self.generation = keep, self.generation + 1
        self.inputs[:, self.size], self.images[:, self.size] = q, image
        self.size += 1


class Span:
    """Directions of one pattern and their images: Ũ orthonormal, M S Ũ = Q T (Q orthonormal, T upper triangular).

    ``used``: the memory's columns already recalled into it; ``generation``: the memory's when it was begun.
    """

    def __init__(self, size: int, used: int, generation: int):
        self.U, self.Q, self.T = np.zeros((size, 0)), np.zeros((size, 0)), np.zeros((0, 0))
        self.used, self.generation = used, generation

    @property
    def nbytes(self) -> int:
        return self.U.nbytes + self.Q.nbytes + self.T.nbytes

    def orthogonal(self, x: np.ndarray) -> np.ndarray | None:
        """The unit part of x ⟂ the directions so far (None when less than ``DEPENDENT`` of it is left)."""
        norm = np.linalg.norm(x)
        for _ in range(2):
            x = x - self.U @ (self.U.T @ x)
        rest = np.linalg.norm(x)
        return x / rest if rest > DEPENDENT * norm and rest > 0 else None

    def extend(self, X: np.ndarray, W: np.ndarray) -> bool:
        """Append directions X with images W = M S X, orthonormalised (dependent ones dropped); False if none is left."""
        norms = np.linalg.norm(X, axis=0)
        X, W = X[:, norms > 0] / norms[norms > 0], W[:, norms > 0] / norms[norms > 0]   # unit columns: QR pivots
        if X.shape[1] == 0:                                                            # on dependence, not scale
            return False
        for _ in range(2):                                      # X ⟂ Ũ; images follow: M S Ũ P = Q T P
            P = self.U.T @ X
            X, W = X - self.U @ P, W - self.Q @ (self.T @ P)
        Qx, Rx, perm = sla.qr(X, mode="economic", pivoting=True, check_finite=False)
        independent = np.abs(np.diag(Rx)) > RECALLED
        rank = len(independent) if independent.all() else int(np.argmin(independent))
        if rank == 0:
            return False
        U = Qx[:, :rank]
        W = sla.solve_triangular(Rx[:rank, :rank], W[:, perm[:rank]].T, trans="T").T   # images of U
        Tn = np.zeros((self.Q.shape[1], rank))
        for _ in range(2):
            step = self.Q.T @ W
            W, Tn = W - self.Q @ step, Tn + step
        Qn, Rn = sla.qr(W, mode="economic", check_finite=False)
        k = self.T.shape[0]
        self.T = np.block([[self.T, Tn], [np.zeros((rank, k)), Rn]])
        self.U, self.Q = np.hstack([self.U, U]), np.hstack([self.Q, Qn])
        return True


class Recycler:
    """GCR with recycling for the Newton systems of one run (see the module docstring).

    The Newton matrix of a pattern is given by ``weights`` (a, b) = (w_a u, w_b u), the inputs of R
    per unit direction u on the contact points, and ``image(u, r)``: M u given r = R(w_a u, w_b u)
    (the identity rows of the points out of contact and the plate's rows cost no product).  With the
    column scaling S, the directions are kept orthonormal, Ũ, and their images as M S Ũ = Q T (Q
    orthonormal, T upper triangular), so that T is as well conditioned as M S; a solve is
    z = S Ũ T⁻¹ Qᵀ b, whose residual is the least-squares one up to round-off.  The spans of the ``SPANS``
    patterns last solved are kept (within ``BYTES``), each for the memory's generation it was begun in.
    """

    def __init__(self, memory: ComplianceMemory):
        self.memory = memory
        self.spans: OrderedDict[bytes, Span] = OrderedDict()          # the pattern solved last, last
        self.shortfall = 0.0

    def solve(self, key, weights, image, scaling: np.ndarray, b: np.ndarray, atol: float,
              max_directions: int = 2000) -> np.ndarray:
        """M z = b solved to ‖M z − b‖∞ ≤ atol (or the best after ``max_directions`` products); ``key``: the pattern.

        The residual is checked through the memory at the end (no product: z's input is in its span).  The
        images of recalled directions are combinations and carry round-off; where that leaves the residual
        above atol, the correction is solved once more on fresh directions only (a new span for the pattern).
        ``shortfall`` is the final ‖M z − b‖∞ / atol (> 1 is logged: an ill-conditioned Newton matrix).
        """
        memory, n = self.memory, self.memory.n
        apply = lambda u, response: image(scaling * u, response)  # noqa: E731 - M S u
        span = self.spans.pop(key, None)
        if span is None or span.generation != memory.generation:
            span = self._begin(len(b), apply, recall=True)
        self._keep(key, span)
        self._recall(span, weights, apply, scaling)
        z = self._minimise(span, b, weights, apply, scaling, atol, max_directions)
        residual = b - image(z, memory(weights[0] * z[:n], weights[1] * z[:n]))
        if np.abs(residual).max() > atol:
            span = self._begin(len(b), apply, recall=False)
            self._keep(key, span)
            z = z + self._minimise(span, residual, weights, apply, scaling, atol, max_directions)
            residual = b - image(z, memory(weights[0] * z[:n], weights[1] * z[:n]))
        self.shortfall = np.abs(residual).max() / atol
        if self.shortfall > 1:
            log.warning("matrix-free Newton step solved to %.1f × its tolerance only (an ill-conditioned Newton "
                        "matrix); Newton's own test decides", self.shortfall)
        return z

    def _keep(self, key, span: Span) -> None:
        """``span`` the pattern's, the most recently used; the least recently used dropped beyond ``SPANS`` or ``BYTES``."""
        self.spans[key] = span
        while len(self.spans) > 1 and (len(self.spans) > SPANS or sum(s.nbytes for s in self.spans.values()) > BYTES):
            self.spans.popitem(last=False)

    def _begin(self, size: int, apply, recall: bool) -> Span:
        """A new span: the plate's unit directions, whose images cost no product; the memory to recall or not."""
        memory, n = self.memory, self.memory.n
        span = Span(size, 0 if recall else memory.size, memory.generation)
        plate = np.zeros((size, size - n))
        plate[n:] = np.eye(size - n)
        span.extend(plate, np.array([apply(u, np.zeros(n)) for u in plate.T]).reshape(-1, size).T)
        return span

    def _minimise(self, span: Span, b, weights, apply, scaling, atol: float, max_directions: int) -> np.ndarray:
        """Least squares in ``span``, then GCR directions S r added to it (a Krylov step at a breakdown)."""
        memory, n = self.memory, self.memory.n
        r = b - span.Q @ (span.Q.T @ b)
        direction = r
        for _ in range(max_directions):
            if np.abs(r).max() <= atol:
                break
            u = span.orthogonal(direction)
            if u is None and span.Q.shape[1]:
                u = span.orthogonal(span.Q[:, -1])
            if u is None:
                break
            v = scaling * u
            if not span.extend(u[:, None], apply(u, memory(weights[0] * v[:n], weights[1] * v[:n]))[:, None]):
                break
            span.used = memory.size                              # the new input is u's: not to be recalled
            r = r - span.Q[:, -1] * (span.Q[:, -1] @ r)
            direction = r
        if not span.U.shape[1]:
            return np.zeros(len(b))
        return scaling * (span.U @ sla.solve_triangular(span.T, span.Q.T @ b))

    def _recall(self, span: Span, weights, apply, scaling: np.ndarray) -> None:
        """Add to ``span`` the remembered inputs (from its ``used`` on) that this pattern produces, with their images."""
        memory, n = self.memory, self.memory.n
        if span.used >= memory.size:
            return
        inputs, images = memory.inputs[:, span.used:memory.size], memory.images[:, span.used:memory.size]
        span.used = memory.size
        w_a, w_b = weights
        a, b = inputs[:n], inputs[n:]
        u = np.zeros((len(scaling), inputs.shape[1]))
        u[:n] = (np.divide(a, w_a[:, None], out=np.zeros_like(a), where=w_a[:, None] > 0)
                 + np.divide(b, w_b[:, None], out=np.zeros_like(b), where=w_b[:, None] > 0)) / scaling[:n, None]
        outside = np.sqrt((a[w_a <= 0] ** 2).sum(axis=0) + (b[w_b <= 0] ** 2).sum(axis=0))
        produced = outside <= NEW
        if produced.any():
            u = u[:, produced]
            span.extend(u, np.column_stack([apply(col, z) for col, z in zip(u.T, images[:, produced].T)]))
