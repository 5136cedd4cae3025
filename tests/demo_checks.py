"""The check of each gallery demo (docs/demos): one number of the demo against a closed form or an independent run.

Each check takes the demo's variables (its globals once it has run) and returns ``(value, expected, tolerance)`` for
``pytest.approx``; never a stored output.  The docs build runs them (``docs/_ext/gallery_files.py`` calls
:func:`record` after each example when ``NGWEAR_DEMO_CHECKS`` names a file) and ``tests/test_demos.py`` asserts
what they recorded, so each demo runs once per test session.
"""
import traceback
from pathlib import Path

import numpy as np


def archard_identity(g):
    """Explicit wear: worn area = k α Σ_{j<N} Σ_i m_i p_{j,i} (the discrete Archard law)."""
    scene, result = g["scene"], g["result"]
    alpha = scene.contact.wear * np.linalg.norm(scene.foundation.velocity)
    k = scene.time.T / scene.time.steps
    return result.wear_volume[-1], k * alpha * (result.pressure[:-1] @ result.weights).sum(), dict(rel=1e-12)


def p1_space_order(g):
    """P1 elements: ‖ε(u − u_h)‖ = O(h) for a smooth solution."""
    return g["orders"]["V_sum"], 1.0, dict(abs=0.2)


def uniform_wear_torque(g):
    """A worn-in pad brakes with μ F (r_i + r_o)/2 (uniform wear), up to O(h²) and the transient left."""
    scene, result = g["scene"], g["result"]
    r_i, r_o = scene.geometry.size[:2]
    force = abs(scene.loads.plate.force[2])
    return -result.torque[-1], scene.contact.friction * force * (r_i + r_o) / 2, dict(rel=1e-3)


def archard_rate(g):
    """Pin on disc: dV/dt = κ ω R F, to (a/R)²/8 = 0.13 %."""
    scene, result = g["scene"], g["result"]
    rate = (result.wear_volume[-1] - result.wear_volume[-2]) / (result.times[-1] - result.times[-2])
    force = abs(scene.loads.plate.force[2])
    return rate, scene.contact.wear * scene.foundation.angular_velocity[2] * scene.geometry.position[0] * force, \
        dict(rel=2e-3)


def translating_archard(g):
    """Sliding at v with no rigid contact: V(T) = κ v F T, whatever the part's shape."""
    scene, result = g["scene"], g["result"]
    assert result.reaction.max() == 0.0, "the layer carries the whole force"
    speed, force = np.linalg.norm(scene.foundation.velocity), abs(scene.loads.plate.force[2])
    return result.wear_volume[-1], scene.contact.wear * speed * force * scene.time.T, dict(rel=1e-9)


def study_case_is_a_run(g):
    """A case of the study = ngwear.simulate of its scene, run here."""
    import ngwear

    case = g["table"].iloc[3]
    scene = ngwear.load_scene(g["FOLDER"] / "paper_strip.toml").replace(**{
        "mesh.maxh": 0.2, "time.steps": 20, "contact.friction": case["contact.friction"],
        "contact.wear": case["contact.wear"]})
    assert g["table"].attrs["summary"]["completed"] == 16
    return case["max_wear"], ngwear.simulate(scene, progress=False).wear.max(), dict(rel=1e-12)


def explorer_run_is_a_run(g):
    """The explorer's run = ngwear.simulate of its scene, run here."""
    import ngwear

    assert (Path("out") / "explorer" / "app.png").stat().st_size > 10_000, "the app's screenshot"
    explorer = g["explorer"]
    return explorer.result.wear_volume[-1], ngwear.simulate(explorer.scene, progress=False).wear_volume[-1], \
        dict(rel=1e-12)


def resume_is_bit_identical(g):
    """Interrupted, resumed: the wear of the uninterrupted run, to the last bit."""
    part, resumed, whole = g["part"], g["resumed"], g["whole"]
    assert part.status == "interrupted" and 0 < part.steps < whole.steps and resumed.steps == whole.steps
    return float(np.abs(resumed.wear - whole.wear).max()), 0.0, dict(abs=0.0)


def trapezoidal_order(g):
    """The trapezoidal rule is of second order in k."""
    return g["orders"]["trapezoidal"], 2.0, dict(abs=0.15)


def life_worn_in(g):
    """A pad's life: half its friction material worn, worn in: the uniform-wear torque μF(r_i + r_o)/2 within 1 %.

    Also the wear rate uniform over the face within 2 % and the volume per MJ κ/μ in every block (Archard).
    """
    scene, result, blocks = g["scene"], g["result"], g["blocks"]
    assert result.completed and g["total"].max() > 0.5 * result.thickness.max()
    assert g["spread"] < 0.02
    assert np.allclose(blocks["volume_per_megajoule"], 1e6 * scene.contact.wear / scene.contact.friction, rtol=1e-3)
    return -result.torque[g["start"]], g["uniform"], dict(rel=0.01)


def disc_recursion(g):
    """The lumped disc: backward Euler of C_d T' = (1 − η) Q − H_d (T − T_∞) on the recorded power, to round-off."""
    scene, result = g["scene"], g["result"]
    f, h, m = scene.foundation, scene.heat, scene.material
    body, disc = np.sqrt(m.conductivity * m.density * m.heat_capacity), np.sqrt(
        f.conductivity * f.density * f.heat_capacity)
    eta = body / (body + disc)                                   # Charron's partition, by hand
    temperature = [h.ambient]
    for dt, into_body in zip(np.diff(result.times), result.heat_flux[1:]):
        power = (1 - eta) / eta * into_body
        temperature.append((f.thermal_mass * temperature[-1] + dt * (power + f.cooling * h.ambient))
                           / (f.thermal_mass + dt * f.cooling))
    assert g["stops"][2]["torque"] < g["stops"][0]["torque"], "the torque fades"
    return result.foundation_temperature, np.array(temperature), dict(rel=1e-10)


CHECKS = {
    "01_paper_strip": archard_identity,
    "02_convergence": p1_space_order,
    "03_brake_pad": uniform_wear_torque,
    "04_pin_on_disc": archard_rate,
    "05_own_step_file": translating_archard,
    "06_study": study_case_is_a_run,
    "07_explorer": explorer_run_is_a_run,
    "08_long_run": resume_is_bit_identical,
    "09_work_precision": trapezoidal_order,
    "10_brake_pad_life": life_worn_in,
    "11_brake_pad_heat": disc_recursion,
}


def record(name: str, variables: dict) -> dict:
    """The check of demo ``name`` as JSON: value, expected, tolerance and its doc, or the error it raised."""
    try:
        value, expected, tolerance = CHECKS[name](variables)
    except Exception:                       # recorded for the test to fail with; the docs build goes on
        return {"name": name, "error": traceback.format_exc(limit=-3)}
    return {"name": name, "value": np.asarray(value).tolist(), "expected": np.asarray(expected).tolist(),
            "tolerance": tolerance, "doc": CHECKS[name].__doc__}
