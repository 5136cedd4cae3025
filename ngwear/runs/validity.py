"""Whether a run stays where its model holds, checked after each recorded step: strains, and a worn-through layer.

Each step costs O(n) on the values every step records (no field is recovered):

* **Strain.** ε̂, the lower bound of the body's largest strain of :mod:`ngwear.numerics.strain` (the mean strain
  across the part between Γ_C and a support facing it along ν).  Above :data:`FAIL` the run stops after that step
  (kept), its status one line naming the likely key (:func:`~ngwear.model.plausibility.softest`): a slip of
  units (``young = 210`` for steel, GPa meant) turns a small-strain run into metres of displacement.  Above
  :data:`WARN` the run goes on, with one warning in ``result.warnings`` (the largest ε̂, its step and time).
  A heated body's strain is blamed on its thermal expansion where α ΔT makes half of ε̂ or more.
* **A worn-through layer.** Where w_i ≥ (1 − :data:`THROUGH`) g the layer is worn through: pressed through
  (z = g) it carries at most p(:data:`THROUGH` g), 1 % of p(g) for a linear law, and the paper's model carries the
  load by the rigid reaction λ, which has neither friction nor wear.  One warning naming ``contact.gap`` with the
  time it first happens and the share of Γ_C's area worn through then and at the end; the log says it once.
"""
from __future__ import annotations

import logging

import numpy as np

from ..model.plausibility import softest, unlikely_modulus
from ..results.units import suffix

log = logging.getLogger(__name__)

WARN = 0.01
"""ε̂ above which a run warns: the small-strain model's error, of the order of the strain, passes 1 %."""
FAIL = 0.10
"""ε̂ above which a run stops: far beyond the small-strain model (a slip of units, most likely)."""
THROUGH = 0.01
"""What is left of the layer, as a share of g, where it counts as worn through."""
ACCURACY = "above 1 %, where the small-strain model loses accuracy"
FIRMER = "try a stiffer material or smaller loads"
HOTTER = "is α in 1/K? try a smaller expansion or less heat"
STRAIN, WORN = ": strains reach at least ", "contact.gap: the layer ("
"""What the warnings of :class:`Validity` hold (to replace those of a resumed run's first part)."""


class Validity:
    """The checks of the module docstring over a run's steps, as they are recorded (the rows kept: at once).

    Attributes
    ----------
    peak : tuple
        (ε̂, step, t) of the step with the largest ε̂ so far (ε̂ = 0: none seen).
    worn : tuple or None
        (t, area share) of the first step with a point worn through.
    last : tuple
        (t, area share) of the last step.
    """

    def __init__(self, result, disc):
        scene = result.scene
        self.scene, self.segments, self.g, self.result = scene, disc.condensation.segments, scene.contact.gap, result
        self.thermal = _expansion(scene)
        self.area = result.weights / result.weights.sum()
        self.peak, self.worn, self.last = (0.0, -1, 0.0), None, (0.0, 0.0)
        self.key, self.modulus = softest(scene)
        if len(result.times):               # the rows a resumed run keeps, all at once (their lines were said)
            times = result.times
            strains = self.segments.estimate(result.normal_displacement, result.plate_displacement)
            shares = self._through(result.wear)
            j, worn = int(np.argmax(strains)), np.flatnonzero(shares)
            self.peak, self.last = (float(strains[j]), j, times[j]), (times[-1], float(shares[-1]))
            self.worn = (times[worn[0]], float(shares[worn[0]])) if len(worn) else None

    def __call__(self, state) -> str | None:
        """Check the state's step (s = ν·u, the plate's δ, the wear w): the run's failure, or None to go on."""
        t = state.instant.t
        self.wear(t, state.wear)
        return self.strain(state.steps, t, state.normal, state.plate)

    def strain(self, j: int, t: float, s, delta) -> str | None:
        """ε̂ of step j: a failure beyond :data:`FAIL`; the log's line when it first passes :data:`WARN`."""
        strain = float(self.segments.estimate(s, delta))
        if strain <= self.peak[0]:
            return None
        said, when = self._strain(strain, j, t)
        if self.peak[0] <= WARN < strain <= FAIL:
            log.warning("%s: %s at %s: %s", self.scene.name, said, when, ACCURACY)
        self.peak = (strain, j, t)
        if strain > FAIL:
            advice = (HOTTER if "thermal expansion" in said else
                      "is it in Pa?" if unlikely_modulus(self.scene, self.modulus) else FIRMER)
            return f"{when}: {said}, beyond the small-strain model ({advice})"
        return None

    def wear(self, t: float, w) -> None:
        """The share of Γ_C worn through at t; the log's line when it first is some."""
        self.last = t, float(self._through(w))
        if self.last[1] and self.worn is None:
            self.worn = self.last
            log.warning("%s: %s", self.scene.name, self._worn())

    def _through(self, w):
        """The share of Γ_C's area where w ≥ (1 − :data:`THROUGH`) g (rows of w: of each)."""
        return (w >= (1 - THROUGH) * self.g) @ self.area

    def warnings(self) -> list[str]:
        """The run's warnings of these checks: strains above :data:`WARN` (if it went on), a worn-through layer."""
        out = []
        if WARN < self.peak[0] <= FAIL:
            said, when = self._strain(*self.peak)
            out.append(f"{said} (the most) at {when}: {ACCURACY}")
        if self.worn is not None:
            out.append(self._worn(final=True))
        return out

    def report(self, result) -> None:
        """Put :meth:`warnings` into ``result.warnings``, in place of those of the steps before a resume."""
        result.warnings[:] = [w for w in result.warnings if STRAIN not in w and not w.startswith(WORN)]
        result.warnings.extend(self.warnings())

    def _strain(self, strain: float, j: int, t: float) -> tuple[str, str]:
        """(``key = value: strains reach at least ε̂ %``, ``step j (t = …)``).

        The key is the thermal expansion's where α ΔT, ΔT the body's highest rise at step j, makes half of ε̂ or
        more (the strain is thermal), else the softest modulus's.
        """
        when = f"step {j} (t = {t:.4g}{suffix(self.scene, 'time')})"
        if self.thermal is not None:
            key, alpha = self.thermal
            rise = float(self.result.max_temperature[j]) - self.scene.heat.start
            if alpha * rise >= 0.5 * strain:
                return (f"{key} = {alpha:g}{suffix(self.scene, 'expansion')}{STRAIN}{100 * strain:.3g} % (thermal "
                        f"expansion: α ΔT = {100 * alpha * rise:.3g} % at ΔT = {rise:.4g}"
                        f"{suffix(self.scene, 'temperature difference')})", when)
        value = "" if self.modulus is None else f" = {self.modulus:g}" + suffix(self.scene, "pressure")
        return f"{self.key}{value}{STRAIN}{100 * strain:.3g} %", when

    def _worn(self, final: bool = False) -> str:
        (t, share), (end, last), time = self.worn, self.last, suffix(self.scene, "time")
        later = f", over {100 * last:.3g} % at t = {end:.4g}{time}" if final and end > t else ""
        return (f"{WORN}g = {self.g:g}{suffix(self.scene, 'length')}) is worn through at t = {t:.4g}{time} over "
                f"{100 * share:.3g} % of Γ_C{later}; beyond it the paper's model carries the load rigidly, without "
                "friction or wear")


def _expansion(scene) -> tuple[str, float] | None:
    """(key, α) of the largest thermal expansion of a heated scene's regions (its own key or the default table's)."""
    if scene.heat.model != "conduction":
        return None
    material, tables = scene.material, scene.material.by_region(scene.geometry.regions)
    region, table = max(tables.items(), key=lambda item: item[1].expansion or 0.0)
    if not table.expansion:
        return None
    own = region in material.regions and material.regions[region].expansion is not None
    return (f"material.regions.{region}.expansion" if own else "material.expansion"), table.expansion

