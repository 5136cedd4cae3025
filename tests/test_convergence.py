"""Mesh-convergence smoke test on the paper's scene: the final wear converges as h shrinks."""
import numpy as np
import pytest

import ngwear


def wear_profile(scene, maxh, x):
    r = ngwear.simulate(scene.replace(**{"mesh.maxh": maxh}), progress=False)
    order = np.argsort(r.contact_points[:, 0])
    return np.interp(x, r.contact_points[order, 0], r.wear[-1, order])


@pytest.mark.slow
def test_final_wear_converges_under_h_refinement(paper_scene):
    scene = paper_scene.replace(**{"time.steps": 20})
    x = np.linspace(0, 3, 601)
    reference = wear_profile(scene, 0.025, x)
    errors = [np.sqrt(np.trapezoid((wear_profile(scene, h, x) - reference) ** 2, x)) for h in (0.4, 0.2, 0.1)]
    assert errors[0] > errors[1] > errors[2]
    rate = np.polyfit(np.log([0.4, 0.2, 0.1]), np.log(errors), 1)[0]
    assert rate > 1.2, f"observed order {rate:.2f} (about 1.7 measured)"
