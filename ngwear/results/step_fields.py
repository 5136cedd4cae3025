"""The per-step result fields, each declared once: its name, its shape per step, its quantity and its meaning.

A run records the rows of :data:`RECORDED` at every step (:mod:`ngwear.results.recording`; in mapped files with an
output folder, :class:`~ngwear.results.recording.History`) and computes the fields :data:`DERIVED` from them (a
:class:`~ngwear.results.result.Result` property of the same name).  ``result.npz`` holds both, a checkpoint the
recorded rows; the units of a scene in SI (:mod:`ngwear.results.units`) and the reference of the result files
(``docs/reference/files.md``) read this table, and so does the table of every per-step number of a run: the fields
whose shape per step is ``()`` and the components of the vectors (:mod:`ngwear.results.history_csv`, ``history.csv``).
A new per-step field is one :class:`StepField` here, and the code that records or
derives it.
"""
from __future__ import annotations

from dataclasses import dataclass

SIZES = {"n": "contact points", "d": "dimension", "r": "plate unknowns"}
"""The letters of a shape per step: what they count."""


@dataclass(frozen=True)
class StepField:
    """One per-step result field: an array of shape (N, *shape), N the completed steps + 1.

    ``shape`` is in the letters of :data:`SIZES` (``()`` a number per step, ``("n",)`` one per contact point);
    ``quantity`` names its unit in an SI scene (a key of :data:`ngwear.results.units.QUANTITIES`; None: a ratio).
    ``parts`` names the components of a vector whose components differ ((name, quantity) each; default: the field's
    name with the axis, ``tangential_force_x``).  ``when`` the runs that record it: every run (None), those with a
    temperature (``"heat"``: ``heat.model = "conduction"``) or those with a contact coefficient of the state
    (``"state"``: T, p or v).
    """

    name: str
    shape: tuple[str, ...]
    quantity: str | None
    doc: str
    parts: tuple[tuple[str, str | None], ...] = ()

    def columns(self, size: int) -> list[tuple[str, str | None]]:
        """(name, quantity) of each of the ``size`` components of a vector per step (a field of shape (k,))."""
        if self.parts:
            return list(self.parts[:size])
        return [(f"{self.name}_{'xyz'[k]}", self.quantity) for k in range(size)]
    when: str | None = None

    def recorded_in(self, scene) -> bool:
        """Whether a run of ``scene`` records this field."""
        from ..model.coefficients import stateful

        if self.when == "heat":
            return scene.heat.model != "none"
        return self.when is None or bool(stateful(scene.contact))

    def size(self, sizes: dict[str, int]) -> tuple[int, ...]:
        """The shape of one step's row for the sizes ``{"n": …, "d": …, "r": …}`` of a run."""
        return tuple(sizes[letter] for letter in self.shape)

    @property
    def shown(self) -> str:
        """The array's shape as the reference writes it, e.g. ``(N,)`` or ``(N, n)``."""
        return "(" + ", ".join(("N", *self.shape)) + (",)" if not self.shape else ")")


RECORDED = (
    StepField("times", (), "time", "t_j of each completed step (not uniform with `time.adaptive`)"),
    StepField("speed_factor", (), None, "s_v, the factor of the foundation's velocity the step was solved with "
                                        "(`foundation.speed_table`, or a programme's stop)"),
    StepField("load_factor", (), None, "s_F, the factor of the loads the step was solved with (`loads.time_table`, or "
                                       "a programme's stop)"),
    StepField("wear", ("n",), "length", "w at the contact points"),
    StepField("normal_displacement", ("n",), "length", "u_ν = u·ν at the contact points"),
    StepField("pressure", ("n",), "pressure", "p(u_ν − d₀ − w), the compliance's traction"),
    StepField("reaction", ("n",), "pressure", "λ ≥ 0, the multiplier of u_ν − d₀ ≤ g (the rigid reaction)"),
    StepField("forces", ("n", "d"), "force", "the contact forces on the body at the points (what recovers u)"),
    StepField("plate_displacement", ("r",), "length", "δ of a rigid plate: its translation along ν, then its tilts "
                                                      "(r = 0: none)",
              parts=(("plate_displacement", "length"), ("plate_tilt_1", "angle"), ("plate_tilt_2", "angle"))),
    StepField("surface_temperature", ("n",), "temperature", "T at the contact points at the step's end (`heat`)",
              when="heat"),
    StepField("max_temperature", (), "temperature", "the body's highest temperature (`heat`)", when="heat"),
    StepField("foundation_temperature", (), "temperature", "T_f, the counterface's temperature (`heat`)", when="heat"),
    StepField("heat_flux", (), "power", "η Σ m_i μ_i p_i ‖v*_i‖: the frictional power into the body (`heat`)", when="heat"),
    StepField("step_friction", ("n",), None, "μ_i of the step, at the last step's state (a coefficient of T, p, "
                                             "v)", when="state"),
    StepField("step_wear_coefficient", ("n",), "wear coefficient", "κ_i of the step, at the last step's state "
                                                                   "(a coefficient of T, p, v)", when="state"),
)
"""The rows a run records at each step, in the order of ``result.npz``."""

DERIVED = (
    StepField("normal_force", (), "force", "Σ m_i (p_i + λ_i): the force the foundation carries"),
    StepField("torque", (), "torque", "Σ m_i μ p_i ((x_i − c) × n*_i)·e: friction moment about the counterface's "
                                      "axis (negative: braking)"),
    StepField("friction_force", (), "force", "|F_t|, the friction force's magnitude"),
    StepField("apparent_friction", (), None, "|F_t| / normal force, the apparent friction coefficient (0 where the "
                                             "normal force is 0; μ where every point slides one way and none is at "
                                             "the bound)"),
    StepField("contact_area", (), "area", "Σ m_i over the points with p_i + λ_i > 0"),
    StepField("wear_volume", (), "volume", "Σ m_i w_i: the worn volume (an area in 2D)"),
    StepField("total_wear", ("n",), "length", "all material removed at the contact points: w and what the geometry "
                                              "updates moved into the body (`wear.geometry = \"surface\"`)"),
    StepField("remaining_thickness", ("n",), "length", "the worn region's thickness along ν under each contact point "
                                                       "(measured once from the mesh) minus `total_wear`"),
    StepField("tangential_force", ("d",), "force", "F_t = Σ m_i μ p_i n*_i: the friction force on the foundation "
                                                   "(against its slip)"),
    StepField("max_wear", (), "length", "the deepest wear: max_i of `total_wear` (w in `wear.geometry = \"layer\"`)"),
    StepField("max_pressure", (), "pressure", "max_i p_i, the peak of the compliance's pressure"),
    StepField("mean_pressure", (), "pressure", "normal force / contact area: the mean traction where in contact (0 "
                                               "without contact)"),
    StepField("friction_power", (), "power", "P = Σ m_i μ_i p_i ‖v*_i‖: the power friction dissipates (|T ω| on a "
                                             "turning counterface, F_t·v on a translating one)"),
    StepField("dissipated_energy", (), "energy", "∫₀ᵗ P dt by the trapezoidal rule over the steps: the energy "
                                                 "friction dissipated so far"),
)
"""What an engineer reads off a part, computed from the rows (what the summary reports at the last step)."""

STEP_FIELDS = RECORDED + DERIVED
