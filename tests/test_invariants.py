"""Invariants and physics of the paper's scene (section 5) at every step."""
import numpy as np

TOL = 1e-9


def test_run_completes_without_nan(paper_result):
    assert paper_result.completed
    assert paper_result.wear.shape == (101, len(paper_result.weights))
    for name in ("wear", "normal_displacement", "pressure", "reaction"):
        assert np.isfinite(getattr(paper_result, name)).all(), name


def test_unilateral_constraint_and_complementarity(paper_result):
    r, g = paper_result, paper_result.scene.contact.gap
    gap = r.normal_displacement - r.d0 - g
    assert gap.max() <= TOL
    assert r.reaction.min() >= 0
    assert np.abs(r.reaction * gap).max() <= 1e-9
    assert (r.reaction > 0).any(), "the paper scene reaches the rigid foundation"


def test_wear_nonnegative_and_nondecreasing(paper_result):
    w = paper_result.wear
    assert w[0].max() == 0
    assert w.min() >= 0
    assert np.diff(w, axis=0).min() >= -1e-15


def test_pressure_is_the_compliance_law(paper_result):
    r = paper_result
    L = r.scene.contact.stiffness
    expected = L * np.maximum(r.normal_displacement - r.d0 - r.wear, 0)
    assert np.allclose(r.pressure, expected, atol=1e-12)


def test_discrete_archard_identity(paper_result):
    """∫ w_{j+1} − ∫ w_j = k α ∫ p(u_ν,j − w_j) with the same nodal quadrature (eq. 15)."""
    r, sc = paper_result, paper_result.scene
    alpha = sc.contact.wear * np.linalg.norm(sc.foundation.velocity)
    lhs = np.diff(r.wear @ r.weights)
    rhs = sc.dt * alpha * (r.pressure[:-1] @ r.weights)
    assert np.allclose(lhs, rhs, rtol=1e-13, atol=1e-16)


def test_body_sinks_and_is_dragged_along_v_star(paper_result):
    u = paper_result.displacement_at([[1.5, 1.0], [3.0, 1.0], [3.0, 0.0]], -1)
    assert (u[:, 1] < 0).all(), "the load (0, -0.1) pushes the body down"
    assert u[1, 0] > 0 and u[2, 0] > 0, "friction drags the free end in the direction of v* = (1, 0)"


def test_layer_worn_through_near_free_end(paper_result):
    r, g = paper_result, paper_result.scene.contact.gap
    x = r.contact_points[:, 0]
    assert (r.normal_displacement - r.d0).max() <= g + TOL
    near_free = x > 2.8
    assert r.wear[-1, near_free].min() > 0.95 * g
    assert r.wear[-1, x < 0.2].max() < 0.2 * g, "little wear next to the clamped end"
    assert r.wear[-1, x > 2].min() > r.wear[-1, x < 1].max(), "wear grows towards the free end"
