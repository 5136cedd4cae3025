"""The shipped brake pads are real pads: friction material on a steel backing plate, pressed on the plate's back.

The friction material is transversely isotropic (brake_pad.toml) or stiffens in compression (brake_pad_compaction.toml).
"""
import ngsolve as ngs
import numpy as np
import pytest
from conftest import ROOT

import ngwear
from ngwear.model.materials import region_laws, young_along
from ngwear.model.scene_mesh import build_mesh

PAD, COMPACTION = ROOT / "geometries" / "brake_pad.toml", ROOT / "geometries" / "brake_pad_compaction.toml"
COARSE = {"mesh.maxh": 0.012, "time.steps": 10, "output.every": 150.0}


def test_brake_pad_is_anisotropic_friction_material_on_a_steel_plate():
    """E = 1 GPa through the thickness (along ν), 2 GPa in-plane; steel 210 GPa; the caliper presses the plate."""
    scene = ngwear.load_scene(PAD)
    laws, nu = region_laws(scene), scene.contact.direction
    assert scene.geometry.regions == ("body", "backing")
    assert young_along(laws["body"], nu) == pytest.approx(1e9, rel=1e-12)
    for in_plane in ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]):
        assert young_along(laws["body"], in_plane) == pytest.approx(2e9, rel=1e-12)
    assert young_along(laws["backing"], nu) == pytest.approx(210e9, rel=1e-12)
    assert laws["body"].monotonicity > 0
    mesh = build_mesh(scene)
    back = ngs.Integrate(ngs.z * ngs.ds("back"), mesh) / ngs.Integrate(ngs.CF(1.0) * ngs.ds("back"), mesh)
    assert scene.loads.plate.boundary == "back" and back == pytest.approx(0.012 + 0.0055, rel=1e-12)
    result = ngwear.simulate(scene.replace(**COARSE), progress=False)
    assert result.completed and np.abs(result.normal_force - 3000.0).max() < 1e-8 * 3000


def test_compaction_pad_is_compressed_everywhere_so_it_is_the_linear_pad_of_lambda_plus_beta():
    """Under the plate tr ε < 0 in the whole friction material: σ = 2η ε + (λ + β) tr(ε) I there, Hooke with λ + β.

    So the nonlinear run equals the linear run of λ + β to the Newton tolerance, and sinks less than β = 0.
    """
    scene = ngwear.load_scene(COMPACTION).replace(**COARSE)
    material = scene.material
    lam, eta = material.lame
    assert material.kind == "compaction" and material.compaction_modulus == pytest.approx(4 * eta, rel=1e-12)
    result = ngwear.simulate(scene, progress=False)
    disc = result.discretization
    for step in (0, -1):
        u = disc.gridfunction(result.displacement(step))
        tension = ngs.Integrate(ngs.IfPos(ngs.Trace(ngs.Grad(u)), 1.0, 0.0), disc.mesh,
                                definedon=disc.mesh.Materials("body"))
        assert tension == 0                                   # no volume of the friction material with tr ε > 0
    hooke = scene.replace(**{"material": {"lame_lambda": lam + material.compaction_modulus, "lame_mu": eta,
                                          "regions": {"backing": {"young": 210e9, "poisson": 0.3}}}})
    linear = ngwear.simulate(hooke, progress=False)
    for name in ("wear", "pressure", "plate_displacement"):
        a, b = getattr(result, name), getattr(linear, name)
        assert np.abs(a - b).max() < 1e-9 * np.abs(b).max(), name
    soft = ngwear.simulate(scene.replace(**{"material.compaction_modulus": 0.0}), progress=False)
    assert result.plate_displacement[-1, 0] < soft.plate_displacement[-1, 0]
