"""The frames of a run whose worn surface moves (``wear.geometry = "surface"``): each shows the body at its step.

The body of frame j is the mesh as built moved by the geometry updates at or before step j: a vertex of Γ_C by the
wear those updates removed there, total_wear − w (P1: the contact points are Γ_C's vertices).  Its displacement is
the one solved at the step, on the mesh of that step: along ν at Γ_C it is the recorded u_ν to round-off (recovered
on the last update's mesh it would be off by ~1 %).  The contact file's face moves with the body.
"""
import numpy as np
import pytest
import pyvista as pv
from test_life import taper_scene

import ngwear
from ngwear.numerics.topology import coordinates
from ngwear.results.vtk import frame_name


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """The tapering pad through 4 geometry updates, a frame every 3.5 steps (the updates' steps among them)."""
    run = ngwear.simulate(taper_scene(T=3.0, steps=30).replace(**{"output.every": 0.35}), progress=False)
    return run, run.save(tmp_path_factory.mktemp("worn"))


def frames(folder, steps, kind="fields"):
    return {j: pv.read(folder / f"{kind}_{frame_name(j)}.vtu") for j in steps}


def test_each_frame_shows_the_body_worn_to_its_step(saved):
    run, folder = saved
    steps = run.stored_steps
    assert run.geometry_updates >= 2 and steps[0] == 0 < run.removed_rows[0]
    assert set(run.removed_rows) & set(steps), "an update's step is a frame (its body moved, its u solved before)"
    nu = np.array([*run.scene.contact.direction, 0.0])
    body = frames(folder, steps)
    built = body[0].points
    on = np.isclose(built @ nu, (built @ nu).max())                   # Γ_C, the face furthest along ν
    points = np.pad(run.contact_points, ((0, 0), (0, 1)))
    at = np.argmin(np.linalg.norm(built[on][:, None] - points[None], axis=2), axis=1)
    assert np.abs(built[on] - points[at]).max() == 0.0, "P1: Γ_C's vertices are the contact points"
    removed = run.total_wear - run.wear
    shown = set()
    for j, frame in body.items():
        assert frame.n_points == len(built)
        assert np.abs(frame.points[on] - (built[on] - np.outer(removed[j, at], nu))).max() < 1e-15, j
        u = frame.point_data["displacement"][on] @ nu[:2]
        assert np.abs(u - run.normal_displacement[j, at]).max() < 1e-15, f"u_ν of step {j}, solved on its mesh"
        shown.add(run.updates_by(j))
    assert shown == set(range(run.geometry_updates + 1)), "every mesh of the run is some frame's"
    assert removed[-1].min() > 0.01 and removed[steps[1]].max() == 0.0
    final = coordinates(ngwear.load_result(folder).discretization.mesh)
    last = body[steps[-1]].points[:, :2]
    assert np.abs(last[:, None] - final[None]).max(axis=2).min(axis=1).max() < 1e-15, "the last frame: mesh.vol"
    assert np.abs(body[0].points[:, :2][:, None] - final[None]).max(axis=2).min(axis=1).max() > 0.01, "the built mesh is not"


def test_the_contact_file_moves_with_the_body(saved):
    run, folder = saved
    nu = np.array([*run.scene.contact.direction, 0.0])
    removed = run.total_wear - run.wear
    points = np.pad(run.contact_points, ((0, 0), (0, 1)))
    for j, face in frames(folder, run.stored_steps, "contact").items():
        assert np.abs(face.points - (points - np.outer(removed[j], nu))).max() < 1e-15, j
        assert np.array_equal(face.point_data["pressure"], run.pressure[j])


def test_a_loaded_surface_run_writes_the_same_frames(saved, tmp_path):
    run, folder = saved
    again = ngwear.load_result(folder)
    assert sorted(again.meshes) == list(range(run.geometry_updates + 1))
    again.save(tmp_path)
    for kind in ("fields", "contact"):
        first, second = frames(folder, run.stored_steps, kind), frames(tmp_path, run.stored_steps, kind)
        for j in run.stored_steps:
            assert np.array_equal(first[j].points, second[j].points), (kind, j)
            assert np.array_equal(first[j].point_data["displacement"], second[j].point_data["displacement"])


def test_the_pictures_draw_each_frame_on_its_worn_body(saved):
    """fig*.png: the renderer is given the frame's body, X of the step's mesh + u, not the last mesh's.

    Under the plate the face stays on the foundation (the plate follows the wear down): the mesh drawn recedes.
    """
    from ngwear.views import render
    from ngwear.views.picture_data import vertex_displacement

    run, _ = saved
    early, late = run.removed_rows[0] - 1, run.stored_steps[-1]
    nu = np.array(run.scene.contact.direction)
    with render.Canvas(field="wear") as canvas:
        for j in (early, late):
            canvas.frame(run, j, render.picture_steps(run))
            drawn = canvas._parts["body"].grid.points[:, :2]                 # what VTK draws
            assert np.array_equal(drawn, run.body_coordinates(j) + vertex_displacement(run, j)), j
    built, final = run.body_coordinates(early), run.body_coordinates(late)
    assert np.array_equal(built, run.meshes[0]) and np.array_equal(final, coordinates(run.discretization.mesh))
    face = (built - final) @ nu                                         # how far each vertex receded, along −ν
    on = np.isclose(built @ nu, (built @ nu).max())
    removed = (run.total_wear - run.wear)[late]
    assert face[on].min() == pytest.approx(removed.min(), rel=1e-12)
    assert face[on].max() == pytest.approx(removed.max(), rel=1e-12)


def test_a_run_makes_again_the_bodies_no_frame_kept(saved):
    """A step between frames draws on its own body: the run rebuilds it from the updates' wear, to the bit."""
    run = saved[0]
    kept = dict(run.meshes)
    try:
        for k in range(1, run.geometry_updates + 1):
            step = int(run.removed_rows[k - 1])                      # the first step on mesh k
            run.meshes.pop(k)
            assert np.array_equal(run.body_coordinates(step), kept[k]), k
    finally:
        run.meshes.update(kept)
