"""Result files: npz/JSON round trip, VTU/PVD series, displacement at stored steps, partial runs."""
import numpy as np
import pytest

import ngwear
from ngwear.results.result import ARRAYS


@pytest.fixture(scope="module")
def small(paper_scene):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 8, "output.every": 0.5})
    return ngwear.simulate(scene, progress=False)


def test_save_and_load_round_trip(small, tmp_path):
    small.save(tmp_path)
    assert (tmp_path / "fields.pvd").is_file() and len(list(tmp_path.glob("fields*.vtu"))) == 3
    back = ngwear.load_result(tmp_path)
    assert back.scene == small.scene and back.status == small.status
    for name in ARRAYS + ("contact_points", "weights"):
        assert np.array_equal(getattr(back, name), getattr(small, name)), name
    data = np.load(tmp_path / "result.npz")
    assert {"wear", "normal_displacement", "pressure", "reaction", "times"} <= set(data.files)
    pts = [[3.0, 1.0], [2.0, 0.0]]
    for step in small.stored_steps:
        assert np.allclose(back.displacement_at(pts, step), small.displacement_at(pts, step), atol=1e-14)


def test_shapes(small):
    n = len(small.weights)
    assert small.contact_points.shape == (n, 2)
    for name in ("wear", "normal_displacement", "pressure", "reaction"):
        assert getattr(small, name).shape == (9, n)
    assert small.stored_steps == [0, 4, 8]


def test_failed_run_keeps_completed_steps(paper_scene, tmp_path):
    """A Newton failure mid-run stops with a message naming the step and keeps what was computed."""
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 10, "solver.max_iterations": 2,
                                   "loads.time_table": [[0, 0], [0.5, 0], [0.6, 1], [1, 1]]})
    r = ngwear.simulate(scene, progress=False)
    assert not r.completed and f"step {r.steps + 1} " in r.status, r.status
    assert r.steps >= 5, "the unloaded steps before t = 0.5 converge"
    assert r.wear.shape[0] == r.steps + 1
    r.save(tmp_path)
    assert ngwear.load_result(tmp_path).status == r.status


def test_displacement_on_contact_boundary(small):
    """Points of Γ_C (shared with the layer) are evaluated from the body side."""
    u = small.displacement_at([[0.0, 0.0], [3.0, 0.0], [1.5, 0.0]], -1)
    assert np.allclose(u[0], 0, atol=1e-12)
    s = -u[1:, 1]
    x = small.contact_points[:, 0]
    for xi, si in zip((3.0, 1.5), s):
        j = np.argmin(abs(x - xi))
        if abs(x[j] - xi) < 1e-12:
            assert abs(small.normal_displacement[-1, j] - si) < 1e-6


def test_the_frames_draw_every_element_of_the_body(small, tmp_path):
    """All of the body is in each VTU: as many cells as NGSolve writes for the mesh without a mask."""
    import re

    import ngsolve as ngs

    small.save(tmp_path)
    mesh = small.discretization.mesh
    ngs.VTKOutput(mesh, coefs=[], names=[], filename=str(tmp_path / "all"),
                  subdivision=small.scene.mesh.order - 1).Do()
    cells = lambda path: int(re.search(rb'NumberOfCells="(\d+)"', path.read_bytes()).group(1))  # noqa: E731
    assert cells(tmp_path / "all.vtu") >= mesh.ne
    for frame in tmp_path.glob("fields*.vtu"):
        assert cells(frame) == cells(tmp_path / "all.vtu"), frame.name
def test_cut_backs_are_counted_and_saved(paper_scene, tmp_path):
    """A step that converges only from a load continuation records how many it tried; files keep the count.

    p = 25 r₊² from the unloaded state: Newton needs more than 10 iterations for step 0 at once, fewer for
    the load cut in 2 and 4 parts.
    """
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 20, "solver.max_iterations": 10,
                                   "contact.law": "power", "contact.exponent": 2.0, "contact.stiffness": 25.0})
    r = ngwear.simulate(scene, progress=False)
    assert r.completed
    cutbacks = [rec.cutbacks for rec in r.newton]
    assert cutbacks[0] >= 1 and sum(cutbacks[1:]) == 0, cutbacks
    assert ngwear.simulate(scene.replace(**{"solver.max_iterations": 50}), progress=False).newton[0].cutbacks == 0
    r.save(tmp_path)
    assert [rec.cutbacks for rec in ngwear.load_result(tmp_path).newton] == cutbacks


def test_a_stop_after_all_cut_backs_says_how_many(paper_scene):
    scene = paper_scene.replace(**{"mesh.maxh": 0.2, "time.steps": 20, "solver.max_iterations": 2})
    r = ngwear.simulate(scene, progress=False)
    assert not r.completed and r.newton[-1].cutbacks == 3
