"""A run's per-step rows in mapped files of its output folder.

The same numbers as in memory, checkpoints that write only what is new, room that grows, and a folder that
holds the history of one run.
"""
import json
import re

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.results.checkpoint import CHECKPOINT
from ngwear.results.folder import FolderError
from ngwear.results.recording import History
from ngwear.results.result import ARRAYS


def small(**changes):
    return ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.steps": 40, **changes})


def histories(folder):
    return sorted(p.name for p in folder.glob("steps-*"))


def test_rows_on_disk_are_the_rows_in_memory(tmp_path):
    in_memory = ngwear.simulate(small(), progress=False)
    on_disk = ngwear.simulate(small(), progress=False, checkpoint=tmp_path)
    [home] = histories(tmp_path)
    for name in ARRAYS:
        rows = getattr(on_disk, name)
        assert np.array_equal(rows, getattr(in_memory, name)), name
        if rows.size:
            assert isinstance(rows, np.memmap) and rows.filename == tmp_path / home / f"{name}.f64", name
    stored = np.fromfile(tmp_path / home / "wear.f64").reshape(-1, len(in_memory.weights))
    assert np.array_equal(stored[:41], in_memory.wear)


def test_a_checkpoint_writes_the_newton_records_not_the_rows(tmp_path):
    """Checkpoints of 40 and of 160 steps differ by the Newton records only: the rows stay in their files."""
    sizes = {}
    for steps in (40, 160):
        folder = tmp_path / str(steps)
        result = ngwear.simulate(small(**{"time.steps": steps, "time.T": steps / 40}), progress=False,
                                 checkpoint=folder)
        sizes[steps] = (folder / CHECKPOINT).stat().st_size
        row = sum(getattr(result, name)[0].nbytes for name in ARRAYS)
    assert sizes[160] - sizes[40] < 120 * row / 4                # a quarter of the 120 steps' rows at most


def test_the_rows_grow_in_their_files(tmp_path):
    history = History.empty({"times": (), "wear": (3,), "plate_displacement": (0,)}, 2, tmp_path)
    for j in range(9):
        wear = history.put("wear", j, [j, 2 * j, 3 * j])
        history.put("times", j, 0.5 * j)
        history.put("plate_displacement", j, [])
    assert wear.shape == (9, 3) and isinstance(wear, np.memmap)
    assert np.array_equal(wear[:, 2], 3 * np.arange(9))
    history.flush()
    again = History.reopen(history.folder, {"times": (), "wear": (3,), "plate_displacement": (0,)}, 9)
    assert len(again.buffers["wear"]) == 14 and again.buffers["plate_displacement"].shape == (9, 0)  # 2 → 6 → 14
    assert np.array_equal(again.buffers["wear"][:9], wear) and np.array_equal(again.buffers["times"][:9],
                                                                              0.5 * np.arange(9))


def test_a_new_run_in_the_folder_replaces_the_old_history(tmp_path):
    ngwear.simulate(small(), progress=False, checkpoint=tmp_path)
    [first] = histories(tmp_path)
    ngwear.simulate(small(**{"contact.friction": 0.5}), progress=False, checkpoint=tmp_path)
    [second] = histories(tmp_path)
    assert second != first
    resumed = ngwear.simulate(small(**{"contact.friction": 0.5, "time.T": 2.0, "time.steps": 80}), progress=False,
                              resume=tmp_path)
    direct = ngwear.simulate(small(**{"contact.friction": 0.5, "time.T": 2.0, "time.steps": 80}), progress=False)
    assert np.array_equal(resumed.wear, direct.wear) and histories(tmp_path) == [second]


def test_resuming_into_another_folder_leaves_the_first_alone(tmp_path):
    first, second = tmp_path / "a", tmp_path / "b"
    short = ngwear.simulate(small(), progress=False, checkpoint=first)
    before = {p.name: p.read_bytes() for p in (first / histories(first)[0]).iterdir()}
    longer = small(**{"time.T": 2.0, "time.steps": 80})
    extended = ngwear.simulate(longer, progress=False, resume=first, checkpoint=second)
    assert extended.completed and extended.steps == 80 and len(histories(second)) == 1
    assert {p.name: p.read_bytes() for p in (first / histories(first)[0]).iterdir()} == before
    assert np.array_equal(extended.wear[:41], short.wear)
    again = ngwear.simulate(longer, progress=False, resume=second)
    assert np.array_equal(again.wear, extended.wear)


def test_rows_are_not_shared_between_results(tmp_path):
    """A later run in the folder neither writes into an earlier result's rows nor takes them away."""
    one = ngwear.simulate(small(), progress=False, checkpoint=tmp_path)
    kept = np.array(one.wear)
    ngwear.simulate(small(**{"contact.friction": 0.5}), progress=False, checkpoint=tmp_path)
    assert np.array_equal(one.wear, kept)


def test_a_run_kept_in_memory_checkpoints_a_copy(tmp_path):
    """The explorer's runs live in memory; saving one writes a history beside its checkpoint to resume from."""
    from ngwear.results.checkpoint import write_checkpoint

    in_memory = ngwear.simulate(small(), progress=False)
    write_checkpoint(tmp_path, in_memory)
    assert not isinstance(in_memory.wear, np.memmap) and len(histories(tmp_path)) == 1
    longer = small(**{"time.T": 2.0, "time.steps": 80})
    resumed = ngwear.simulate(longer, progress=False, resume=tmp_path)
    assert np.array_equal(resumed.wear, ngwear.simulate(longer, progress=False).wear)


def test_a_checkpoint_holding_its_rows_is_refused(tmp_path):
    """A checkpoint.npz with the rows in it, not in files of their own, is not ngwear's: one line naming what it lacks."""
    part = ngwear.simulate(small(), progress=False)
    x, lam, step = (part.continuation[key] for key in ("x", "lam", "step"))
    np.savez(tmp_path / CHECKPOINT, **part.arrays(), x=x, lam=lam, step=np.array(step),
             scene=np.array(json.dumps(part.scene.to_dict())))
    part.discretization.mesh.ngmesh.Save(str(tmp_path / "mesh.vol"))
    with pytest.raises(FolderError, match=rf"^resume: {re.escape(str(tmp_path / CHECKPOINT))} is damaged or not a "
                                          r"checkpoint of ngwear \(no rows, history, checksums, mesh_sha256\)$"):
        ngwear.simulate(small(**{"time.T": 2.0, "time.steps": 80}), progress=False, resume=tmp_path)
