"""Reference tables generated from the code while the site builds, so that they cannot drift from it.

* ``{scene-keys} SECTION`` — the keys of one table of a scene file: the rows of
  :func:`ngwear.model.reference.reference_table` (the declarations) whose key is in SECTION (``name`` for the
  top-level keys ``name`` and ``units``), with the level a change of the key invalidates (its declared ``invalidates``).
* ``{result-keys} FILE`` — the keys of ``result.npz``, ``summary.json`` or ``checkpoint.npz`` with their
  meaning (the per-step fields': their declarations, :mod:`ngwear.results.step_fields`).  The keys are those of
  files really written by a small run at build time; a key the code writes that :data:`MEANING` does not explain,
  or one it explains that the code no longer writes, fails the build.
* ``{contact-fields} contact_stepNNN.vtu`` — the point fields of the contact file, from their declarations
  (:data:`ngwear.results.contact_file.CONTACT_FIELDS`), with their SI units (:mod:`ngwear.results.units`).
* :func:`cli_parser` — ``ngwear``'s argument parser for sphinx-argparse, its plain help texts (read in a terminal)
  turned into reST.

A table cell's ``|`` is escaped (:func:`ngwear.model.reference.markdown_row`): unescaped, Markdown splits the row there.
"""
from __future__ import annotations

import argparse
import json
import re
import tempfile
from functools import cache
from pathlib import Path

import numpy as np
from docutils import nodes
from docutils.statemachine import StringList
from sphinx.errors import ExtensionError
from sphinx.util.docutils import SphinxDirective

from ngwear.model.reference import markdown_row
from ngwear.results.step_fields import STEP_FIELDS

MEANING = {
    "result.npz": {
        **{f.name: (f.shown, f.doc) for f in STEP_FIELDS},      # the per-step fields, as declared
        "contact_points": ("(n, d)", "x_i, the contact points"),
        "friction_coefficient": ("(n,)", "μ_i at the contact points (`contact.friction`, a number or a field)"),
        "wear_coefficient": ("(n,)", "κ_i at the contact points (`contact.wear`)"),
        "contact_stiffness": ("(n,)", "L_i at the contact points (`contact.stiffness`)"),
        "weights": ("(n,)", "m_i, their quadrature weights: ∫_ΓC f ≈ Σ m_i f_i"),
        "newton_iterations": ("(N,)", "Newton iterations of each step"),
        "newton_converged": ("(N,)", "whether each step's Newton converged"),
        "newton_active": ("(N,)", "size of the active set (points held at u_ν − d₀ = g) at each step's last iteration"),
        "newton_damped": ("(N,)", "iterations of each step whose Newton step was shortened by the line search"),
        "newton_lengths": ("(N,)", "length of each step's residual history in `newton_residuals`"),
        "newton_residuals": ("(Σ lengths,)", "the residual histories, concatenated"),
        "newton_bulk": ("(N,)", "a nonlinear material's bulk iterations in each step (images u = G(u); 0: linear)"),
        "newton_tangents": ("(N,)", ("tangent stiffnesses taken in the run up to each step, factorised or low-rank "
                                   "updates (nonlinear material)")),
        "newton_cutbacks": ("(N,)", "load cut-backs each step needed before its Newton converged (0: none)"),
        "status": ("()", "`completed`, `interrupted`, `worn_out` (`wear.limit` reached; a warning says when and where), "
                         "or the message of the step that failed"),
        "wall_time": ("()", "seconds the run took: meshing, factorising and the time loop"),
        "solve_time": ("()", "seconds of the time loop alone"),
        "rejected": ("()", "rejected steps of an adaptive run"),
        "warnings": ("(·,)", "warnings of the run (e.g. the explicit update's stability)"),
        "mesh_sha256": ("()", "SHA-256 of `mesh.vol` beside it: read only with the mesh it was computed on"),
        "jumped": ("(·,)", "a `[programme]` with `programme.jump`: the stops applied at once, not simulated (they "
                           "record no rows; see `stops.csv`)"),
        "thickness": ("(n,)", "the worn region's thickness along ν under each contact point, measured once on the mesh "
                              "as built (`remaining_thickness` is this minus `total_wear`)"),
        "removed_rows": ("(U,)", "`wear.geometry = \"surface\"`: the steps after which the geometry was updated"),
        "removed": ("(U, n)", "the wear each update moved from the layer into the body, at the contact points "
                              "(`total_wear` = `wear` + their sum up to the step)"),
        "moved_weights": ("(U, n)", "the contact points' weights m_i after each update (the forces' and volumes' "
                                    "from the step after it)"),
        "field_steps": ("(F,)", "the frames: steps whose full displacement is stored"),
        "fields": ("(F, DOFs)", "the displacement's DOF vector at each frame"),
        "frame_coordinates": ("(F, vertices, d)", "`wear.geometry = \"surface\"`: the vertices of the body at each "
                                                  "frame, the mesh moved by the updates at or before its step (the "
                                                  "frames are written on it); empty (0, 0, d) without an update"),
        "temperature_fields": ("(F, P1 DOFs)", "only with `heat`: the nodal temperature (P1) at each frame"),
        "units": ("()", "only for a scene with `units = \"SI\"`: the unit of each key, as JSON (`{\"torque\": "
                        "\"N·m\", …}`)"),
        "provenance": ("()", "the ngwear, NGSolve and Python versions that computed it and the SHA-256 of its scene's "
                             "canonical JSON, as JSON (`{\"ngwear\": \"0.1.0\", …, \"scene_sha256\": …}`)"),
    },
    "summary.json": {
        "status": ("", "as in result.npz"),
        "steps": ("", "index of the last completed step"),
        "contact_points": ("", "n"),
        "end_time": ("", "t of the last step"),
        "torque_peak": ("", "the whole run's torque of the largest magnitude (its sign kept: negative brakes)"),
        "torque_mean": ("", "the torque's mean over the run's time, 1/(t_N − t_0) ∫ T dt (trapezoidal rule)"),
        "friction_force_peak": ("", "the largest |F_t| of the run"),
        "friction_force_mean": ("", "the mean of |F_t| over the run's time"),
        "pressure_peak": ("", "the largest p of the run (over the points and steps)"),
        "pressure_mean": ("", "the mean over the run's time of the mean contact pressure (normal force / contact area)"),
        "dissipated_energy": ("", "∫ P dt, P = Σ m_i μ_i p_i ‖v*_i‖ (∫ |T ω| dt on a turning counterface, ∫ F_t·v dt "
                                  "on a translating one)"),
        "wear_volume": ("", "the worn volume at the end (an area in 2D)"),
        "wear_mass": ("", "ρ × the worn volume, only where `material.density` of the regions carrying Γ_C gives one ρ"),
        "gap_reached_at": ("", "the first step time at which max w reached g (to 1 %: w approaches g only "
                               "asymptotically); null: never"),
        "max_wear": ("", "max over the run of w"),
        "max_penetration": ("", "max over the run of u_ν − d₀ (≤ g)"),
        "gap": ("", "g"),
        "normal_force": ("", "at the last step"),
        "torque": ("", "at the last step (0 where the counterface is at rest)"),
        "friction_force": ("", "|F_t| at the last step"),
        "apparent_friction": ("", "|F_t| / normal force at the last step"),
        "contact_area": ("", "at the last step"),
        "max_pressure": ("", "max p at the last step"),
        "mean_pressure": ("", "normal force / contact area at the last step"),
        "friction_power": ("", "P at the last step"),
        "plate_displacement": ("", "δ at the last step (only with `loads.plate`)"),
        "contact_fraction": ("", "share of the points with p > 0 at the last step"),
        "active_fraction": ("", "share of the points with λ > 0 (u_ν − d₀ = g) at the last step"),
        "rejected_steps": ("", "rejected steps (only with `time.adaptive`)"),
        "remaining_thickness_min": ("", "the least remaining thickness over Γ_C at the last step"),
        "remaining_thickness_mean": ("", "its mean over Γ_C (weights m_i)"),
        "remaining_thickness_max": ("", "its largest value"),
        "geometry_updates": ("", "`wear.geometry = \"surface\"`: how often the worn surface moved (0: `layer`)"),
        "stops_simulated": ("", "a `[programme]`: the stops simulated to their end (0 without a programme)"),
        "stops_jumped": ("", "the stops applied at once by cycle jumps"),
        "max_temperature": ("", "only with `heat`: the body's highest temperature over the run"),
        "max_temperature_time": ("", "only with `heat`: when it was reached"),
        "max_foundation_temperature": ("", "only with `heat`: the counterface's highest temperature over the run"),
        "max_foundation_temperature_time": ("", "only with `heat`: when it was reached"),
        "newton_iterations_total": ("", "all Newton iterations of the converged steps"),
        "newton_iterations_max": ("", "the most of one step"),
        "wall_time_s": ("", "seconds the run took: meshing, factorising and the time loop"),
        "solve_time_s": ("", "seconds of the time loop alone"),
        "materials": ("", "each region's material by name (`body`, `backing`, a file's): `law`, its constants under "
                          "their scene keys (`young`, `poisson`, `compaction_modulus`, …) and the law's `m_F` and "
                          "`L_F` (H(F)); an `energy` law's estimated over the run's frames, with `estimated`, the "
                          "number of sampled tangents"),
        "warnings": ("", "every warning of the run, as `ngwear run` prints them: the plausibility of an SI scene's "
                         "numbers, the stability of the wear update, where the model's validity ends, a layer "
                         "worn through (a list; empty: none)"),
        "provenance": ("", "`ngwear`, `ngsolve`, `python`: the versions that computed the run; `scene_sha256`: the "
                           "SHA-256 of the scene's canonical JSON (keys sorted, no spaces, UTF-8), as `scene.json` "
                           "gives it"),
        "units": ("", "only for a scene with `units = \"SI\"`: the unit of each number above (`{\"torque\": "
                      "\"N·m\", …}`)"),
    },
    "checkpoint.npz": {
        "rows": ("()", "how many steps count"),
        "history": ("()", "name of the `steps-<id>` folder whose files hold the steps' rows"),
        "x": ("(·,)", "the solver's unknowns at the last step (its warm start)"),
        "lam": ("(n,)", "λ at the last step"),
        "step": ("()", "the adaptive clock's next step size"),
        "scene": ("()", "the scene, as JSON"),
        "checksums": ("()", "CRC-32 of each file of the steps' rows, as JSON: a damaged row file is refused"),
        "heat_temperature": ("(P1 DOFs,)", "only with `heat`: the nodal temperature at the last step"),
        "heat_heat": ("(5,)", "only with `heat`: its time, the last step's frictional power, the heat supplied, "
                              "convected and removed with the worn material (`wear.geometry = \"surface\"`) so far"),
        "heat_counterface": ("(·,)", "only with `heat`: a lumped counterface's T_f, heat received and cooled (none: "
                                     "given)"),
        "temperature_steps": ("(·,)", "only with `heat`: the steps whose nodal temperature is kept for the frames"),
        "temperature_fields": ("(·, P1 DOFs)", "only with `heat`: those temperatures"),
        "heat_friction_reference": ("(n,)", "only with a `contact.friction` of T, p or v: the reference μ whose "
                                            "Newton matrices refine the steps' (a programme with `heat` also keeps "
                                            "`heat_started_*`, the heat's state at the last simulated stop's start)"),
    },
}
HEADER = ("contact_points weights newton_iterations newton_converged newton_active newton_damped newton_lengths "
          "newton_residuals newton_cutbacks newton_bulk newton_tangents friction_coefficient wear_coefficient "
          "contact_stiffness mesh_sha256 status wall_time solve_time rejected warnings provenance jumped thickness "
          "removed_rows removed moved_weights").split()
MEANING["checkpoint.npz"] = {**{k: MEANING["result.npz"][k] for k in HEADER}, **MEANING["checkpoint.npz"]}


def scene_key_rows(section: str) -> list[str]:
    """The rows of the declared reference table whose key is in ``section`` (``name``: the top-level keys)."""
    from ngwear.model.reference import reference_table

    rows = reference_table().splitlines()[2:]
    if section == "name":                       # the top-level keys: name, units
        return [row for row in rows if "." not in row.split("`")[1]]
    return [row for row in rows if row.startswith(f"| `{section}.")]


def scene_key_table(section: str) -> str:
    """The Markdown table of ``section``'s keys, with what a change of each invalidates."""
    from ngwear.model.sections import declared_keys

    levels = {name: info.json_schema_extra["invalidates"] for name, info in declared_keys()}
    rows = scene_key_rows(section)
    if not rows:
        raise ExtensionError(f"scene-keys: no declared key in section {section!r}")
    lines = ["| key | meaning | default | allowed | a change rebuilds |", "|---|---|---|---|---|"]
    for row in rows:
        name = row.split("`")[1]
        lines.append(f"{row} {levels.get(name, 'nothing')} |")
    return "\n".join(lines)


@cache
def written_keys() -> dict[str, list[str]]:
    """The keys of the files a small run writes: a strip under a plate, adaptive, checkpointed, in SI, heated.

    Its friction depends on the temperature; the keys only a run with ``heat`` (or such a coefficient) writes say so.
    """
    import ngwear

    scene = ngwear.Scene.from_dict({
        "name": "reference", "units": "SI", "mesh": {"maxh": 0.5},
        "material": {"conductivity": 1.0, "density": 2.0, "heat_capacity": 1.0},
        "contact": {"friction": "0.5 - 0.001 * T", "wear": 1.0},
        "loads": {"plate": {"boundary": "top", "force": [0.0, -0.3]}},
        "heat": {"model": "conduction", "partition": 0.5}, "time": {"T": 0.2, "steps": 4, "adaptive": True}})
    with tempfile.TemporaryDirectory() as folder:
        result = ngwear.simulate(scene, progress=False, checkpoint=folder)
        result.save(folder)
        out = Path(folder)
        with np.load(out / "result.npz") as data, np.load(out / "checkpoint.npz") as checkpoint:
            return {"result.npz": list(data.keys()), "checkpoint.npz": list(checkpoint.keys()),
                    "summary.json": list(json.loads((out / "summary.json").read_text()))}


def result_key_table(name: str) -> str:
    """The Markdown table of a result file's keys; an error when the code and :data:`MEANING` disagree."""
    if name not in MEANING:
        raise ExtensionError(f"result-keys: unknown file {name!r} (known: {', '.join(MEANING)})")
    keys, meaning = written_keys()[name], MEANING[name]
    unexplained, gone = set(keys) - set(meaning), set(meaning) - set(keys)
    if unexplained or gone:
        raise ExtensionError(f"result-keys {name}: written but not explained: {sorted(unexplained)}; explained but "
                             f"not written: {sorted(gone)} (update docs/_ext/ngwear_reference.py)")
    shaped = name.endswith(".npz")
    lines = ["| key | shape | meaning |" if shaped else "| key | meaning |", "|---|---|---|" if shaped else "|---|---|"]
    for key in keys:
        shape, text = meaning[key]
        lines.append(markdown_row((f"`{key}`", shape, text) if shaped else (f"`{key}`", text)))
    return "\n".join(lines)


def contact_field_table(_name: str) -> str:
    """The Markdown table of the contact file's point fields, as declared."""
    from ngwear.results.contact_file import CONTACT_FIELDS
    from ngwear.results.units import QUANTITIES

    lines = ["| array | components | unit | what |", "|---|---|---|---|"]
    for f in CONTACT_FIELDS:
        unit = QUANTITIES[f.quantity][0] if f.quantity else "—"
        lines.append(markdown_row((f"`{f.name}`", str(f.components), unit, f.doc + (" (with `heat`)" if f.heat else ""))))
    return "\n".join(lines)


def rest(text: str | None) -> str | None:
    """A help text in reST: `code` as a literal, and addresses (``tcp://host:8786``) literal too, not links."""
    if not text:
        return text
    parts = re.split(r"`([^`]+)`", text)          # odd parts: the code spans
    for k in range(0, len(parts), 2):
        parts[k] = re.sub(r"\b([a-z][a-z0-9+.-]*://[^\s,;)]+)", r"``\1``", parts[k])
    for k in range(1, len(parts), 2):
        parts[k] = f"``{parts[k]}``"
    return "".join(parts)


def cli_parser() -> argparse.ArgumentParser:
    """``ngwear``'s parser (:func:`ngwear.cli.commands._parser`), every description and help text in reST (:func:`rest`)."""
    from ngwear.cli.commands import _parser

    def convert(parser):
        parser.description = rest(parser.description)
        for action in parser._actions:
            action.help = rest(action.help)
            if isinstance(action, argparse._SubParsersAction):
                for choice in action._choices_actions:
                    choice.help = rest(choice.help)
                for sub in action.choices.values():
                    convert(sub)
        return parser

    return convert(_parser())


class _Table(SphinxDirective):
    required_arguments = 1
    make = staticmethod(str)

    def run(self):
        container = nodes.container()
        self.state.nested_parse(StringList(self.make(self.arguments[0]).splitlines()), self.content_offset, container)
        return container.children


class SceneKeys(_Table):
    make = staticmethod(scene_key_table)


class ResultKeys(_Table):
    make = staticmethod(result_key_table)


class ContactFields(_Table):
    make = staticmethod(contact_field_table)


def setup(app):
    app.add_directive("scene-keys", SceneKeys)
    app.add_directive("result-keys", ResultKeys)
    app.add_directive("contact-fields", ContactFields)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
