"""An explicit wear update known to diverge (k·α·L > 2) is refused up front, unless the scene allows it."""
import numpy as np
import pytest
from conftest import ROOT
from test_cli import assert_one_line_error, ngwear

import ngwear as ng
from ngwear.model.compliance import largest_slope
from ngwear.numerics.discrete import Discretization
from ngwear.numerics.wear import diverging, explicit_stability, steps_cap
from ngwear.runs.checks import k_alpha_slope

pytestmark = pytest.mark.hostile

PAD = ROOT / "geometries" / "brake_pad.toml"


def test_millimetres_typed_for_metres_are_refused_with_the_remedy(tmp_path):
    """The pad 1000× too large: α = κωr 1000× too; k·α·L = 60.  One line naming time.steps, exit 2, no output.

    The line ends with the likeliest cause: the plate's force, a mean contact pressure of 0.458 Pa over the huge face.
    """
    proc = ngwear("run", PAD, "--set", "geometry.size=[100,150,60,12]", "geometry.backing=5.5", "mesh.maxh=6",
                  "--quiet", "--out", tmp_path / "out", cwd=tmp_path)
    assert_one_line_error(proc, "time.steps")
    assert "k·α·L = 60 > 2 diverges" in proc.stderr
    assert "wear.integrator = 'implicit' or 'trapezoidal'" in proc.stderr and "wear.allow_unstable" in proc.stderr
    assert "time.steps >= 9000" in proc.stderr       # k·α·L ≤ 1: 60 × the scene's 150 steps
    assert "; the likeliest cause: loads.plate.force = [0.0, 0.0, -3000.0] (a mean contact pressure of 0.458 Pa" \
        in proc.stderr
    assert not (tmp_path / "out").exists()


def test_the_rate_is_the_largest_over_the_contact_points(paper_scene):
    """On a turning disc α = κ|ω|r is largest at the outer radius; the foundation's translation alone gives 0."""
    pad = ng.load_scene(PAD).replace(**{"mesh.maxh": 0.012, "time.steps": 20, "contact.wear": 1.6e-10})
    contact = Discretization(pad).contact
    alpha = contact.alpha(contact.coefficients, contact.motion.largest_speed).max()
    assert k_alpha_slope(pad) == 0.0
    radius = max(np.hypot(*Discretization(pad).points.coords[:, :2].T))
    assert alpha == pytest.approx(pad.contact.wear * 50.0 * radius, rel=1e-12)
    rate = alpha * largest_slope(pad.contact)
    assert Discretization(pad).contact.largest_rate() == pytest.approx(rate, rel=1e-12)
    r = pad.dt * rate
    message = diverging(pad, rate)
    assert r > 2 and message.startswith(f"time.steps: explicit wear with k·α·L = {r:.3g} > 2 diverges")
    assert diverging(pad.replace(**{"wear.allow_unstable": True}), rate) is None
    assert diverging(pad.replace(**{"wear.integrator": "implicit"}), rate) is None
    assert diverging(pad.replace(**{"time.steps": int(np.ceil(20 * r / 2))}), rate) is None


def test_remedies_stay_within_the_caps(paper_scene):
    """L = 1e8: k·α·L = 1.5e8 at N = 100, N ≥ 1.5e10 would be needed — beyond time.steps ≤ 1e6: not suggested."""
    stiff = paper_scene.replace(**{"contact.stiffness": 1e8})
    rate = 1.5 * 1e8                                      # α L
    assert steps_cap() == 1_000_000
    for text in (diverging(stiff, rate), explicit_stability(stiff, rate),
                 explicit_stability(stiff.replace(**{"wear.integrator": "trapezoidal"}), rate)):
        assert text.startswith("time.steps:") and "time.steps >=" not in text and "'implicit'" in text
    assert "time.steps >= 1500" in diverging(paper_scene.replace(**{"time.steps": 10, "contact.wear": 150.0}), 1500.0)


def test_allowed_it_runs_with_the_warning_and_overshoots(paper_scene):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10, "contact.wear": 3.0})
    with pytest.raises(ng.SceneError, match=r"^time\.steps: explicit wear with k·α·L = 3 > 2 diverges"):
        ng.simulate(scene, progress=False)
    result = ng.simulate(scene.replace(**{"wear.allow_unstable": True}), progress=False)
    assert result.completed and any("diverges" in w for w in result.warnings)
    assert result.wear.max() > scene.contact.gap, "the explicit update wears past the layer"


def test_adaptive_explicit_runs_are_never_refused(paper_scene):
    """The clock keeps the explicit step below 1/(αL): nothing to refuse."""
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 1, "time.adaptive": True,
                                   "wear.integrator": "explicit"})
    assert diverging(scene, 15.0) is None
