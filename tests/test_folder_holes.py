"""The output folders, closed: nothing ngwear writes follows a link planted at one of its names.

Others who can write into a shared output folder can plant links there; a run neither writes through them nor
truncates a file that is not its own.  Leftovers of runs killed outright go with the next run, a new run leaves
nothing of an earlier one, ``--out`` with ``--resume`` goes on in a copy, ``verify`` holds its folder, and the
app's template files refuse a path that leaves them.
"""
import asyncio
import os
import threading

import numpy as np
import pytest
from conftest import PAPER

import ngwear
from ngwear.cli import main
from ngwear.results.folder import LOCK, FolderError, hold
from ngwear.results.recording import Recording

pytestmark = pytest.mark.hostile


def small(**changes):
    return ngwear.load_scene(PAPER).replace(**{"mesh.maxh": 0.2, "time.steps": 10, **changes})


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A small run saved with its checkpoint (10 steps, frames at t = 0, 0.25, …, 1)."""
    out = tmp_path_factory.mktemp("run") / "out"
    result = ngwear.simulate(small(), checkpoint=out, progress=False)
    result.save(out)
    return result, out


def victim(tmp_path, text="precious\n"):
    path = tmp_path / "victim.txt"
    path.write_text(text)
    return path


def test_a_planted_lock_link_is_refused_and_its_target_kept(tmp_path):
    target = victim(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    (out / LOCK).symlink_to(target)
    with pytest.raises(FolderError, match=r"^--out: .*/out/\.ngwear\.lock is a symbolic link, not a lock of ngwear"):
        with hold(out, "--out"):
            pass
    (out / LOCK).unlink()
    os.link(target, out / LOCK)                 # a second name of someone's file
    with pytest.raises(FolderError, match=r"is not a lock of ngwear \(a link file\): remove it$"):
        with hold(out, "--out"):
            pass
    assert target.read_text() == "precious\n"


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to give the lock file another owner")
def test_another_users_lock_file_is_locked_but_never_written(tmp_path):
    lock = tmp_path / LOCK
    lock.write_text("theirs\n")
    os.chown(lock, 65534, 65534)
    with hold(tmp_path, "--out"):
        assert lock.read_text() == "theirs\n"
    assert lock.read_text() == "theirs\n"


def test_files_are_written_under_new_names_never_through_planted_links(run, tmp_path):
    """Links at names ngwear writes (and at main's predictable temporary names): replaced, never followed."""
    from ngwear.views import plots

    result, _ = run
    target = victim(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    written = ["result.npz", "scene.json", "summary.json", "mesh.vol", "fields.pvd", "fields_step010.vtu", "wear.png"]
    for name in [*written, *(f".{stem}.{os.getpid()}.tmp.{ext}" for stem, ext in
                             (("result", "npz"), ("scene", "json"), ("mesh", "vol")))]:
        (out / name).symlink_to(target)
    result.save(out)
    plots.wear_profiles(result, out / "wear.png")
    assert target.read_text() == "precious\n"
    assert not any((out / name).is_symlink() for name in written)
    assert np.array_equal(ngwear.load_result(out).wear, result.wear)


def test_leftovers_of_a_killed_run_go_when_the_folder_is_held(tmp_path):
    left = [tmp_path / f".result.{os.getpid() + 1}.tmp.npz", tmp_path / ".summary.12.0a1b2c3d.tmp.json"]
    for path in left:
        path.write_bytes(b"half")
    scratch = tmp_path / ".fields-k2j4_x9q"
    scratch.mkdir()
    (scratch / "fields_step000.vtu").write_text("half")
    mine = tmp_path / "notes.tmp.txt"
    mine.write_text("the user's")
    with hold(tmp_path, "--out"):
        assert sorted(p.name for p in tmp_path.iterdir()) == [LOCK, "notes.tmp.txt"]


def test_a_new_run_leaves_nothing_of_an_earlier_one(run, tmp_path):
    """The earlier run's results, frames and pictures go before the new run writes (here it stops after step 2)."""
    import shutil

    _, earlier = run
    out = tmp_path / "out"
    shutil.copytree(earlier, out)
    for name in ("fig1_step003.png", "wear.png", "fields_step010.vtu"):
        (out / name).write_bytes(b"the earlier run's")
    stop = threading.Event()
    calls = []

    def stopping(self, *args):
        calls.append(None)
        if len(calls) == 3:
            stop.set()
        return append(self, *args)

    append = Recording.append
    Recording.append = stopping
    try:
        result = ngwear.simulate(small(**{"time.steps": 20}), checkpoint=out, progress=False, stop=stop)
    finally:
        Recording.append = append
    assert result.status == "interrupted" and result.steps == 2
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith("steps-")) == [
        LOCK, "checkpoint.npz", "mesh.vol"]


def test_out_with_resume_goes_on_in_a_copy(run, tmp_path, capsys):
    """The resumed folder stays as it was; the copy holds the run to the last bit, as if it had never stopped."""
    _, first = run
    before = {p.name: p.read_bytes() for p in first.iterdir() if p.is_file()}
    copy = tmp_path / "copy"
    status = main(["run", "--resume", str(first), "--out", str(copy), "--set", "time.T=1.5", "time.steps=15", "--quiet",
                   "--no-pictures", "--no-check"])
    assert status == 0, capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in first.iterdir() if p.is_file()} == before
    straight = ngwear.simulate(small(**{"time.T": 1.5, "time.steps": 15}), progress=False)
    assert np.array_equal(ngwear.load_result(copy).wear, straight.wear)


def test_an_error_in_the_resumed_folder_names_it(run, tmp_path, capsys):
    import shutil

    _, first = run
    folder = tmp_path / "resumed"
    shutil.copytree(first, folder)
    (folder / "summary.json").unlink()
    (folder / "summary.json").mkdir()           # a file the resumed run cannot replace
    status = main(["run", "--resume", str(folder), "--quiet", "--no-pictures", "--no-check"])
    err = capsys.readouterr().err.strip()
    assert status == 2 and "\n" not in err
    assert err == f"ngwear: --resume: cannot write {folder}/summary.json (Is a directory)"


def test_a_resumed_history_file_that_is_a_link_is_refused(run, tmp_path):
    """A link to a copy of the rows (same size and checksum) would have had the resumed run write through it."""
    import shutil

    _, first = run
    folder = tmp_path / "resumed"
    shutil.copytree(first, folder)
    rows = next(folder.glob("steps-*")) / "wear.f64"
    target = tmp_path / "victim.f64"
    shutil.copy(rows, target)
    before = target.read_bytes()
    rows.unlink()
    rows.symlink_to(target)
    with pytest.raises(FolderError, match=r"wear\.f64 is a link, not a file of the run's own"):
        ngwear.simulate(small(**{"time.T": 1.5, "time.steps": 15}), resume=folder, progress=False)
    assert target.read_bytes() == before


def test_verify_holds_its_folder(tmp_path, capsys):
    out = tmp_path / "verify"
    held, release = threading.Event(), threading.Event()

    def holder():
        with hold(out, "x"):
            held.set()
            release.wait(60)

    thread = threading.Thread(target=holder)
    thread.start()
    try:
        held.wait(60)
        status = main(["verify", str(PAPER), "--quick", "--out", str(out)])
    finally:
        release.set()
        thread.join()
    assert status == 2
    assert capsys.readouterr().err.strip() == (f"ngwear: --out: {out} is in use by ngwear (PID {os.getpid()}, "
                                               "another thread)")
    assert not out.exists(), "verify wrote nothing there (the holder, which made it, removed it)"


def test_a_template_path_that_leaves_the_templates_is_404_without_a_traceback(caplog):
    pytest.importorskip("voila")
    import tornado.httpclient
    import tornado.testing
    import tornado.web
    from tornado.httpserver import HTTPServer

    from ngwear.views.app_server import TemplateFiles

    async def fetch(paths):
        socket, port = tornado.testing.bind_unused_port()
        server = HTTPServer(tornado.web.Application([(r"/voila/templates/(.*)", TemplateFiles)]))
        server.add_sockets([socket])
        client = tornado.httpclient.AsyncHTTPClient()
        try:
            return [(await client.fetch(f"http://127.0.0.1:{port}/voila/templates/{path}", raise_error=False)).code
                    for path in paths]
        finally:
            server.stop()

    codes = asyncio.run(fetch(["ngwear/static/..%2f../etc/passwd", "ngwear/static/../../../etc/passwd", "lab",
                               "lab/static/voila.js"]))
    assert codes == [404, 404, 404, 200]
    assert not [r for r in caplog.records if r.exc_info]
