"""Cycle jumps: the stops of a block applied many at once, once their wear increments settle.

A stop maps the wear w at the contact points to w + Δw(w), Δw_i = ∫_stop κ_i ‖v*_i‖ p_i dt (its steps solved: a
*simulated* stop).  The stops of a block are one problem (:mod:`ngwear.model.programme`), so they approach a
periodic state in which Δw changes slowly from stop to stop; once two consecutive simulated stops differ by less
than the tolerance,

    max_i |Δw_k,i − Δw_k−1,i| < τ max_i |Δw_k,i|        (τ = ``programme.jump_tolerance``),

the next N stops are applied at once, w += N Δw_k, and stops are simulated again: a jump is one explicit Euler
step of size N in "stop time" for dw/dk = Δw(w) (``docs/guide/life.md``).

**The accuracy bound.**  Its error is that of the Euler step: the increments change along the jump by
Δw(w_k+m) − Δw(w_k) ≈ m J Δw_k, J = ∂Δw/∂w, so the jump misses

    e_N = Σ_{m<N} m J Δw_k ≈ ½ N² J Δw_k.

J is how the pressure answers a change of wear: p = p(u_ν − d₀ − w) falls by L per unit of wear (L the layer's
slope), softened by the body (the points around move with it), and not at all for a change the body follows
rigidly: a plate's translation (uniform wear) and, with ``tilt``, its rotations (wear affine over Γ_C); a clamped
body follows none.  With Π the projection onto those rigid wear fields and c_i = κ_i s_i L_i (s_i = ∫_stop ‖v*_i‖ dt
the stop's sliding distance at x_i, so c_i is the relative change of the increment per unit of relative wear):

    |J δ|_i ≤ c_i |(I − Π) δ|_i,

taking the layer's full slope L (the body's softening only lowers it).  A jump then changes the increment (the
pressure) by at most N |c ∘ (I − Π) Δw_k| over its stops; bounding that change by :data:`PRESSURE_CHANGE` of the
increment,

    N ≤ PRESSURE_CHANGE · max|Δw_k| / max_i c_i |(I − Π) Δw_k|_i,

bounds the jump's error by |e_N| ≤ ½ PRESSURE_CHANGE · N max|Δw_k|: half a per cent of the wear it applies, so the
worn volume and the thickness of a run with jumps stay within 1 % of stop by stop however many jumps it makes.  In
the worn-in state the increment is rigid ((I − Π)Δw → 0: every point wears at the plate's speed) and only the
block's end, the layer left (``"layer"``), the next geometry update and ``wear.limit`` bound N.  The same bound
tames the Euler step's instability on the fast modes (c_i N > 2): such a mode has decayed within a stop to |e| with
|(I − Π)Δw| ≈ c |e|, so a jump scales it by at most N c ≤ PRESSURE_CHANGE max|Δw| / |e|, and the re-check after the
jump (a simulated stop against the last simulated one, their change per stop within τ) sees the rest.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

PRESSURE_CHANGE = 0.01
"""The largest change of the wear increment (of the pressure) a jump may cause, relative to the increment."""
SHORTEST = 2
"""The fewest stops worth a jump (fewer are simulated)."""


def settled(increment: np.ndarray, previous: np.ndarray, tolerance: float, apart: int = 1) -> bool:
    """Whether two simulated stops ``apart`` stops apart changed their increment by less than τ per stop."""
    scale = np.abs(increment).max(initial=0.0)
    return scale > 0 and np.abs(increment - previous).max() < tolerance * apart * scale


def rigid_modes(points: np.ndarray, nu, plate: bool, tilt: bool) -> np.ndarray:
    """The wear fields a body follows rigidly at the contact points (n × r).

    None when clamped; a plate's translation (a uniform wear); with ``tilt`` its rotations too (a wear affine in the
    coordinates ⟂ ν).
    """
    points = np.asarray(points, dtype=float)
    if not plate:
        return np.zeros((len(points), 0))
    nu = np.asarray(nu, dtype=float)
    plane = np.linalg.svd(nu[None, :])[2][1:]                       # an orthonormal basis of the plane ⟂ ν
    columns = [np.ones(len(points))] + (list(((points - points.mean(axis=0)) @ plane.T).T) if tilt else [])
    return np.column_stack(columns)


def non_rigid(increment: np.ndarray, modes: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """(I − Π) Δw on the points that wore (0 elsewhere), Π the weighted least-squares projection onto ``modes``."""
    wore = increment > 0
    rest = np.where(wore, increment, 0.0)
    if modes.shape[1] and wore.any():
        root = np.sqrt(weights[wore])
        coefficients = np.linalg.lstsq(modes[wore] * root[:, None], increment[wore] * root, rcond=None)[0]
        rest[wore] -= modes[wore] @ coefficients
    return rest


def accurate_stops(increment: np.ndarray, rate: np.ndarray, modes: np.ndarray, weights: np.ndarray) -> float:
    """The accuracy bound N ≤ PRESSURE_CHANGE max|Δw| / max c |(I − Π)Δw| (see the module; inf when rigid)."""
    response = np.abs(rate * non_rigid(increment, modes, weights)).max(initial=0.0)
    scale = np.abs(increment).max(initial=0.0)
    return math.inf if response <= 1e-12 * scale * np.abs(rate).max(initial=1.0) else PRESSURE_CHANGE * scale / response


def room(increment: np.ndarray, left: np.ndarray | float) -> float:
    """The stops of this increment that fit into ``left`` (per point; inf where nothing wears)."""
    wearing = increment > 0
    if not wearing.any():
        return math.inf
    return float(np.min(np.broadcast_to(left, increment.shape)[wearing] / increment[wearing]))


@dataclass
class CycleJumps:
    """What the time loop asks after each simulated stop: how many of the block's next stops to apply at once.

    Call :meth:`simulated` with each simulated stop's index, block and increment, then :meth:`length`; a result
    N ≥ :data:`SHORTEST` means: add N × the increment, count those stops as jumped, call :meth:`jumped`, and
    simulate the stop after them.
    """

    tolerance: float
    _last: tuple | None = None          # (stop, block, increment) of the last simulated stop
    _settled: bool = False

    def simulated(self, stop: int, block: int, increment: np.ndarray) -> None:
        """Record a simulated stop: settled against the last simulated stop of its block (per stop between)."""
        increment = np.asarray(increment, dtype=float)
        last = self._last
        self._settled = last is not None and last[1] == block and settled(increment, last[2], self.tolerance,
                                                                         stop - last[0])
        self._last = (stop, block, increment)

    def length(self, left: int, rate: np.ndarray, modes: np.ndarray, weights: np.ndarray,
               to_update: np.ndarray | float = math.inf, to_limit: np.ndarray | float = math.inf) -> int:
        """N, the stops to apply at once now (0: simulate the next one).

        Parameters
        ----------
        left : int
            The block's stops after the last simulated one.
        rate : ndarray
            c_i = κ_i s_i L_i of a stop (the relative change of its increment per unit relative wear).
        modes, weights : ndarray
            The rigid wear fields (:func:`rigid_modes`) and the contact points' weights m_i.
        to_update, to_limit : ndarray or float
            Per point, the wear left before the next geometry update and before a hard bound: ``wear.limit``, and
            in ``"layer"`` the layer's end (w ≤ g).
        """
        if not self._settled:
            return 0
        increment = self._last[2]
        bound = min(left, accurate_stops(increment, rate, modes, weights), room(increment, to_update),
                    room(increment, to_limit))
        n = int(math.floor(bound))
        return n if n >= SHORTEST else 0

    def jumped(self) -> None:
        """After a jump: the next simulated stop is compared with the last simulated one, per stop between them."""
        self._settled = False
