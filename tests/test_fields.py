"""Contact coefficients that vary over Γ_C in whole runs: closed forms, Archard's identity, the forms.

μ, κ and L as numbers, expressions in x, y, z, arrays over the contact points or callables; the expression
grammar itself is tested in test_expressions.py.
"""
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ngwear

ROOT = Path(__file__).resolve().parents[1]
SCRIPT = Path(sys.executable).with_name("ngwear")
COMMAND = [str(SCRIPT)] if SCRIPT.exists() else [sys.executable, "-m", "ngwear"]

OMEGA, MU, FORCE = 50.0, 0.4, 3000.0       # the shipped brake pad: ω about z, μ, the plate's force
K0 = 6e-12                                 # κ = K0 / r: α = κ ω r = K0 ω = 3e-10 1/Pa, α L = 3 1/s


def stiff_pad(**changes):
    """The shipped pad (annular sector r ∈ [0.10, 0.15], plate force 3 kN, L = 1e10, ω = 50) on a near-rigid body.

    E = 1e13, ν = 0: ρ = L t / E = 1.2e-5, so the layer alone sets the pressure, uniform to O(ρ) under the plate.
    """
    return ngwear.load_scene("brake_pad").replace(**{
        "mesh.maxh": 0.012, "time.T": 1.0, "time.steps": 10, "output.every": 1.0,
        "material": {"young": 1e13, "poisson": 0.0}, **changes})     # near-rigid friction material and backing


def radii(result):
    return np.hypot(*result.contact_points[:, :2].T)


def spread(pressure):
    """(max − min) / mean of p at each step."""
    return np.ptp(pressure, axis=1) / pressure.mean(axis=1)


# ---------------------------------------------------------------- κ ∝ 1/r on a turning pad


def test_wear_coefficient_against_radius_keeps_the_pressure_and_torque_uniform():
    """κ = K0 / r: α_i = κ_i ω r_i = K0 ω everywhere, so a uniform pressure wears uniformly and stays uniform.

    Closed forms (m_i the weights, A = Σ m_i, r̄ = Σ m_i r_i / A): p = F/A, T = −μ F r̄ and w(t_j) = K0 ω t_j F/A
    at every step.  The same pad with the uniform κ = K0/r̄ (the same α at r̄) runs in towards p r = const: its
    pressure spreads (> 20 % after α L T = 3) and its torque falls below μ F r̄.
    """
    field = ngwear.simulate(stiff_pad(**{"contact.wear": "6e-12 / hypot(x, y)"}), progress=False)
    assert field.completed and not field.warnings
    r, m = radii(field), field.weights
    assert np.allclose(field.wear_coefficient, K0 / r, rtol=1e-14, atol=0)
    alpha = field.wear_coefficient * OMEGA * r
    assert np.ptp(alpha) <= 1e-14 * alpha.mean()
    area, mean_radius = m.sum(), (m * r).sum() / m.sum()
    assert np.allclose(field.normal_force, FORCE, rtol=1e-9) and np.all(field.reaction == 0)    # 1e-10 with the backing
    assert spread(field.pressure).max() < 1e-4                                     # 1.0e-5 measured (ρ = 1.2e-5)
    assert np.allclose(field.pressure, FORCE / area, rtol=1e-4)
    assert np.allclose(field.torque, -MU * FORCE * mean_radius, rtol=1e-6)          # 5e-9 measured
    worn = K0 * OMEGA * field.times * FORCE / area
    assert field.wear[-1].min() > 0.1 * field.scene.contact.gap
    assert np.allclose(field.wear, worn[:, None], rtol=1e-4, atol=0)

    uniform = ngwear.simulate(stiff_pad(**{"contact.wear": K0 / mean_radius}), progress=False)
    assert uniform.completed
    assert spread(uniform.pressure)[-1] > 0.2                                      # 0.40 measured
    harmonic = area / (m / r).sum()                                                # fully run in: p r = const
    assert MU * FORCE * harmonic < -uniform.torque[-1] < (1 - 5e-3) * MU * FORCE * mean_radius


def test_a_compliant_pad_runs_in_to_uniform_pressure_with_the_wear_field():
    """E = 1 GPa, ν = 0.25 (the shipped pad): p starts ~10 % from uniform; with α uniform the worn-in state is p = F/A.

    w' = α p with α the same at every point and the plate moving rigidly: the steady state wears uniformly, so p is
    uniform, and the torque tends to −μ F r̄.  Implicit steps, α L T = 12.
    """
    pad = ngwear.load_scene("brake_pad").replace(**{
        "mesh.maxh": 0.012, "time.T": 4.0, "time.steps": 16, "output.every": 4.0, "wear.integrator": "implicit",
        "contact.wear": "6e-12 / hypot(x, y)"})
    result = ngwear.simulate(pad, progress=False)
    assert result.completed
    s = spread(result.pressure)
    assert s[0] > 0.03 and s[-1] < 1e-3 * s[0] and np.all(np.diff(s) < 0)          # 0.10 → 2.3e-5 measured
    r, m = radii(result), result.weights
    assert result.torque[-1] == pytest.approx(-MU * FORCE * (m * r).sum() / m.sum(), rel=1e-6)
    rate = np.diff(result.wear[-2:], axis=0)[0]
    assert np.ptp(rate) < 1e-3 * rate.mean()                                        # it wears uniformly


# ---------------------------------------------------------------- a μ field with two zones


INNER_OUTER = "where(hypot(x, y) < 0.125, 0.2, 0.6)"


def test_two_friction_zones_give_the_zone_weighted_torque():
    """μ = 0.2 inside r = 0.125, 0.6 outside: T = −Σ_i μ_i m_i p_i r_i, and each zone's torque is the uniform run's scaled.

    On the near-rigid pad p = F/A whatever μ (the friction's pull on the pressure is O(ρ)), so the torque is the
    closed form −F/A (0.2 Σ_inner m r + 0.6 Σ_outer m r) and, zone by zone, (μ_zone / 0.4) times the uniform-μ run's.
    """
    zones = ngwear.simulate(stiff_pad(**{"contact.friction": INNER_OUTER, "contact.wear": 0.0, "time.steps": 1}),
                            progress=False)
    uniform = ngwear.simulate(stiff_pad(**{"contact.wear": 0.0, "time.steps": 1}), progress=False)
    r, m, p = radii(zones), zones.weights, zones.pressure
    inner = r < 0.125
    assert 0 < inner.sum() < len(r)
    mu = np.where(inner, 0.2, 0.6)
    np.testing.assert_array_equal(zones.friction_coefficient, mu)
    assert np.allclose(zones.torque, -(p * mu * m * r).sum(axis=1), rtol=1e-13, atol=0)
    moments = -MU * uniform.pressure * m * r                                       # the uniform run's, per point
    assert np.allclose(moments.sum(axis=1), uniform.torque, rtol=1e-13, atol=0)
    scaled = 0.2 / MU * moments[:, inner].sum(axis=1) + 0.6 / MU * moments[:, ~inner].sum(axis=1)
    assert np.allclose(zones.torque, scaled, rtol=1e-6)
    area = m.sum()
    closed = -FORCE / area * ((0.2 * m * r)[inner].sum() + (0.6 * m * r)[~inner].sum())
    assert np.allclose(zones.torque, closed, rtol=1e-6)
    assert np.abs(zones.torque / uniform.torque - 1).min() > 0.05                  # the zones matter


def test_zone_torque_is_the_sum_over_the_points_on_a_compliant_pad():
    """The shipped pad (E = 1 GPa, wear running in): Result.torque = −Σ_i μ_i m_i p_i r_i at every step.

    Computed here from the result's arrays (n*_i is −e_θ, its moment arm −r_i); the apparent friction lies between
    the zones' μ.
    """
    pad = ngwear.load_scene("brake_pad").replace(**{
        "mesh.maxh": 0.012, "time.T": 20.0, "time.steps": 5, "output.every": 20.0, "contact.friction": INNER_OUTER})
    result = ngwear.simulate(pad, progress=False)
    assert result.completed and result.wear[-1].max() > 0
    r, m = radii(result), result.weights
    mu = np.where(r < 0.125, 0.2, 0.6)
    assert spread(result.pressure)[0] > 0.03                                        # not uniform
    assert np.allclose(result.torque, -(result.pressure * mu * m * r).sum(axis=1), rtol=1e-13, atol=0)
    assert np.all((0.2 < result.apparent_friction) & (result.apparent_friction < 0.6))


# ---------------------------------------------------------------- Archard's identity with fields


ARCHARD = {
    "strip": ("paper_strip", {"mesh.maxh": 0.2, "time.T": 0.4, "time.steps": 16,
                              "contact.wear": "1.5 * (1 + 0.5 * sin(3 * x))", "contact.stiffness": "10 * (1 + 0.2 * x)",
                              "contact.friction": "where(x < 1.5, 1, 0.5)"}),
    "pad": ("brake_pad", {"mesh.maxh": 0.012, "time.T": 1.0, "time.steps": 16, "output.every": 1.0,
                          "contact.wear": "8e-12 / hypot(x, y) * (1 + 0.5 * cos(40 * x))",
                          "contact.stiffness": "1e10 * where(y > 0.05, 2, 1)"}),
}


@pytest.mark.parametrize("name", list(ARCHARD))
def test_archards_identity_holds_to_round_off_with_fields(name):
    """Explicit wear with κ and L fields: ∫w_{j+1} − ∫w_j = k Σ m_i α_i p_i(j) to round-off.

    At every point w_{j+1} − w_j = k α_i p_i(j), α_i = κ_i ‖v*(x_i)‖; and p_i = L_i (u_ν − d₀ − w)₊ with the field
    L_i.  κ, L and ‖v*‖ are computed here from the expressions and the foundation's motion (strip: v* = (1, 0);
    pad: ω × x).
    """
    shipped, changes = ARCHARD[name]
    result = ngwear.simulate(ngwear.load_scene(shipped).replace(**changes), progress=False)
    assert result.completed and result.scene.wear.integrator == "explicit" and not result.warnings
    x, y = result.contact_points[:, 0], result.contact_points[:, 1]
    if name == "strip":
        kappa, stiffness, speed = 1.5 * (1 + 0.5 * np.sin(3 * x)), 10 * (1 + 0.2 * x), np.ones_like(x)
    else:
        kappa = 8e-12 / np.hypot(x, y) * (1 + 0.5 * np.cos(40 * x))
        stiffness, speed = 1e10 * np.where(y > 0.05, 2, 1), OMEGA * np.hypot(x, y)
    assert np.allclose(result.wear_coefficient, kappa, rtol=1e-14, atol=0)
    assert np.allclose(result.contact_stiffness, stiffness, rtol=1e-14, atol=0)
    assert np.ptp(kappa) > 0.5 * kappa.mean() and np.ptp(stiffness) > 0.2 * stiffness.mean()
    alpha, k = kappa * speed, np.diff(result.times)[:, None]
    increments = np.diff(result.wear, axis=0)
    predicted = k * alpha * result.pressure[:-1]
    assert np.abs(increments - predicted).max() <= 1e-12 * result.wear.max()
    volume = np.diff(result.wear @ result.weights)
    assert np.allclose(volume, predicted @ result.weights, rtol=1e-12, atol=0)
    assert volume.min() > 0
    compression = result.normal_displacement - result.d0 - result.wear
    pressure = stiffness * np.maximum(compression, 0.0)
    assert np.abs(result.pressure - pressure).max() <= 1e-10 * result.pressure.max()


# ---------------------------------------------------------------- the forms of a coefficient


def strip(**changes):
    return ngwear.load_scene("paper_strip").replace(**{"mesh.maxh": 0.25, "time.steps": 6, "time.T": 0.3,
                                                       "output.every": 0.3, **changes})


def results_of(scenes):
    return [ngwear.simulate(scene, progress=False) for scene in scenes]


def test_number_expression_array_and_callable_give_identical_runs():
    """The same values as a number, an expression, an array over the points and a callable: bit-for-bit the same run.

    Constant μ = 0.5, L = 10 and a varying κ (1.5 (1 + 0.5 sin 3x)): the array is the callable's values at the
    points of the scene's mesh, the callable computes what the expression does, with the same numpy operations.
    """
    points = ngwear.Discretization(strip()).points.coords

    def friction(p):
        return np.full(len(p), 0.5)

    def stiffness(p):
        return np.full(len(p), 10.0)

    def wear(p):
        return 1.5 * (1 + 0.5 * np.sin(3 * p[:, 0]))

    forms = {
        "number": {"contact.friction": 0.5, "contact.stiffness": 10.0},
        "expression": {"contact.friction": "1 / 2", "contact.stiffness": "10",
                       "contact.wear": "1.5 * (1 + 0.5 * sin(3 * x))"},
        "array": {"contact.friction": list(friction(points)), "contact.stiffness": list(stiffness(points)),
                  "contact.wear": list(wear(points))},
        "callable": {"contact.friction": friction, "contact.stiffness": stiffness, "contact.wear": wear},
    }
    forms["number"]["contact.wear"] = forms["expression"]["contact.wear"]      # κ varies: no number for it
    runs = dict(zip(forms, results_of(strip(**changes) for changes in forms.values())))
    reference = runs["expression"]
    assert reference.completed and reference.wear[-1].max() > 0 and np.ptp(reference.wear_coefficient) > 1
    for name, result in runs.items():
        assert result.completed, name
        for array in ("friction_coefficient", "wear_coefficient", "contact_stiffness", "wear", "pressure",
                      "normal_displacement", "reaction", "forces", "torque", "friction_force"):
            np.testing.assert_array_equal(getattr(result, array), getattr(reference, array), err_msg=f"{name} {array}")


# ---------------------------------------------------------------- a field negative somewhere


NEGATIVE = "1.5 * (1 - x)"                   # κ < 0 on the strip's Γ_C where x > 1


def first_negative(points):
    """The first contact point (in the mesh's order) where the expression is negative, and its value there."""
    values = 1.5 * (1 - points[:, 0])
    i = int(np.flatnonzero(values < 0)[0])
    return points[i], values[i]


def check_refusal(line, points):
    """One line naming contact.wear, the range and the first point off, with its value."""
    found = re.fullmatch(r"contact\.wear: must be >= 0 at every contact point \(got (\S+) at \(([^()]+)\)\)", line)
    assert found, line
    value, at = float(found[1]), np.array([float(v) for v in found[2].split(", ")])
    point, expected = first_negative(points)
    assert at == pytest.approx(point, abs=1e-5)
    assert value == pytest.approx(expected, rel=1e-5) and value < 0


def test_negative_wear_field_is_refused_in_python():
    scene = strip(**{"contact.wear": NEGATIVE})
    points = ngwear.Discretization(strip()).points.coords
    with pytest.raises(ngwear.SceneError) as err:
        ngwear.simulate(scene, progress=False)
    check_refusal(str(err.value), points)


@pytest.mark.parametrize("how", ["file", "set"])
def test_negative_wear_field_is_refused_by_the_cli_in_one_line(tmp_path, how):
    """``ngwear run``: exit 2, exactly one line ``ngwear: contact.wear: ...`` naming the first point, no traceback."""
    text = (ROOT / "geometries" / "paper_strip.toml").read_text()
    if how == "file":
        text = text.replace("wear = 1.5", f'wear = "{NEGATIVE}"')
        sets = []
    else:
        sets = [f'contact.wear="{NEGATIVE}"']
    (tmp_path / "scene.toml").write_text(text)
    proc = subprocess.run([*COMMAND, "run", "scene.toml", "--quiet", "--no-pictures", "--set", "mesh.maxh=0.25",
                           "time.steps=6", "time.T=0.3", "output.every=0.3", *sets],
                          cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ngwear: contact.wear: "), proc.stderr
    check_refusal(lines[0].removeprefix("ngwear: "), ngwear.Discretization(strip()).points.coords)


# ---------------------------------------------------------------- every path sees the fields


def test_full_dense_and_matrix_free_paths_agree_with_fields():
    """μ, κ and L fields through the three solvers of a step: equal to 1e-9 of each array's max (tolerance 1e-10).

    The full NGSolve system (μ n* and L as nodal functions), the dense condensed path and the matrix-free one
    (measured: 1e-13 and 8e-11); with μ = 1 everywhere instead of the field the pressure moves by 40 %.
    """
    shipped, changes = ARCHARD["strip"]
    scene = ngwear.load_scene(shipped).replace(**changes)
    dense = ngwear.simulate(scene, discretization=ngwear.Discretization(scene, contact_solve="dense"), progress=False)
    krylov = ngwear.simulate(scene, discretization=ngwear.Discretization(scene, contact_solve="krylov"),
                             progress=False)
    full = ngwear.simulate(scene.replace(**{"solver.method": "full"}), progress=False)
    assert dense.completed and krylov.completed and full.completed
    assert dense.reaction.max() > 0 or dense.wear.max() > 0.1 * scene.contact.gap
    for other in (krylov, full):
        for name in ("normal_displacement", "wear", "pressure", "reaction"):
            a, b = getattr(other, name), getattr(dense, name)
            assert np.abs(a - b).max() <= 1e-9 * max(np.abs(b).max(), 1e-300), name
    uniform = ngwear.simulate(scene.replace(**{"contact.friction": 1.0}), progress=False)
    assert np.abs(uniform.pressure - dense.pressure).max() > 0.1 * dense.pressure.max()
