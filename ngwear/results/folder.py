"""An output folder: held by one run at a time, and what goes wrong with its files.

A run (``simulate(checkpoint=...)``, ``resume``, ``ngwear run``, the explorer's *save result*) holds its
folder for its whole duration: an exclusive ``flock`` on ``.ngwear.lock`` there, which holds the PID and
host of the holder.  A second run into the folder is refused, naming the holder; the kernel releases the
lock when its process ends, however it ends, so the lock of a dead process is simply taken over.  On NFS,
Linux turns ``flock`` into a whole-file POSIX lock held by the server (NFSv4, or NLM for v3), so runs on
different machines exclude each other too, unless the file system is mounted with ``nolock`` (then each
machine only excludes its own runs).  Within a process the lock is re-entrant for the thread that holds
it (the CLI holds the folder around ``simulate``, which holds it again) and refused to other threads.

A full disk ends a run with :class:`NoSpace`, which says what was kept; a damaged or foreign file of a
folder is a :class:`FolderError` naming it (a run's ``mesh.vol`` is known by its :func:`digest`).

Others may write into a shared folder too, so nothing ngwear writes there follows a link planted at a name it
uses: the lock is opened with ``O_NOFOLLOW`` and refused unless it is a regular file with one name, and written
only when it is the user's own; every other file is written under a new name of its own (:func:`replacing`:
created exclusively, never an existing file) and renamed onto its name, which replaces a link instead of
writing through it.  Holding a folder removes what runs killed outright left there (:data:`LEFTOVERS`: their
temporary files and scratch folders), and a new run removes the files of an earlier one (:func:`clear`), so that
a folder never mixes two runs.
"""
from __future__ import annotations

import errno
import fcntl
import hashlib
import os
import re
import secrets
import shutil
import socket
import threading
import zipfile
import zlib
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path
from stat import S_ISREG

import numpy as np

from ..model.scene import SceneError

LOCK = ".ngwear.lock"
NO_SPACE = (errno.ENOSPC, errno.EDQUOT)

_held: dict[Path, list] = {}        # folder → [thread, depth, open lock file]
_guard = threading.Lock()


class FolderError(SceneError):
    """A folder in use, or a file of it that is missing, damaged or from another run; ``key`` names the argument."""

    def __init__(self, key: str, message: str):
        super().__init__(f"{key}: {message}")
        self.key, self.message = key, message

    def named(self, key: str) -> str:
        """The message with the argument called ``key`` (the CLI's flag for a Python argument)."""
        return f"{key}: {self.message}"


class NoSpace(OSError):
    """The disk filled during a run; the message says which steps are kept.

    ``result``: the run so far; ``resumable``: whether its folder's checkpoint lets it go on.
    """

    def __init__(self, message: str, result=None, resumable: bool = False):
        super().__init__(errno.ENOSPC, message)
        self.result, self.resumable = result, resumable

    def __str__(self) -> str:
        return self.strerror


def no_space(err: BaseException) -> bool:
    """Whether ``err`` is a full disk (or quota)."""
    return isinstance(err, OSError) and err.errno in NO_SPACE


@contextmanager
def hold(folder, key: str, create: bool = True):
    """Hold ``folder`` for the block, or raise a FolderError naming its holder.

    ``create``: make the folder if missing (an output folder; removed again when the block wrote nothing
    into it, e.g. a refused run); else (a folder to read from) a missing or read-only folder is not held:
    no run of ours writes there.
    """
    folder = Path(folder)
    made = create and not folder.exists()
    if create:
        folder.mkdir(parents=True, exist_ok=True)
    elif not folder.is_dir() or not os.access(folder, os.W_OK):
        yield folder
        return
    path, me = folder.resolve(), threading.get_ident()
    with _guard:
        entry = _held.get(path)
        if entry is not None and entry[0] != me:
            raise FolderError(key, f"{folder} is in use by ngwear (PID {os.getpid()}, another thread)")
        if entry is None:
            entry = _held[path] = [me, 0, _take(folder, key)]
        entry[1] += 1
    try:
        yield folder
    finally:
        with _guard:
            entry[1] -= 1
            if not entry[1]:
                del _held[path]
                if made and [p.name for p in folder.iterdir()] == [LOCK]:
                    (folder / LOCK).unlink()            # still locked: nobody takes it in between
                    folder.rmdir()
                entry[2].close()                    # releases the lock


def _take(folder: Path, key: str):
    """The open lock file of ``folder``, locked and, when it is the user's own file, holding our PID."""
    path = folder / LOCK
    try:                                            # not truncated: a refused run reads the holder from it
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o644)
    except OSError as err:
        if err.errno != errno.ELOOP:
            raise
        raise FolderError(key, f"{path} is a symbolic link, not a lock of ngwear: remove it") from None
    file = os.fdopen(fd, "r+")
    try:
        stat = os.fstat(fd)
        if not S_ISREG(stat.st_mode) or stat.st_nlink != 1:
            raise FolderError(key, f"{path} is not a lock of ngwear (a {'link' if stat.st_nlink > 1 else 'special'} "
                                   "file): remove it")
        fcntl.flock(file, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        file.seek(0)
        holder = file.read().split()
        file.close()
        raise FolderError(key, f"{folder} is in use by ngwear ({_holder(holder)})") from None
    except BaseException:
        file.close()
        raise
    if stat.st_uid == os.geteuid():                 # another user's lock file is locked, never written
        file.seek(0)
        file.truncate()
        file.write(f"{os.getpid()} {socket.gethostname()}\n")
        file.flush()
        os.fsync(file.fileno())                     # on NFS: to the server, where a refused run reads it
    _remove_leftovers(folder)
    return file


LEFTOVERS = re.compile(r"^(\..+\.\d+(\.[0-9a-f]{8})?\.tmp(\.\w+)?|\.fields-\w+)$")
"""What a run killed outright (SIGKILL) leaves: ``.result.<pid>.tmp.npz`` (and ``.<name>.<pid>.<random>.tmp.<ext>``,
:func:`replacing`'s), ``.fields-<random>/`` (the frames being written)."""
OUTPUTS = ("result.npz", "scene.json", "summary.json", "history.csv", "checkpoint.npz", "mesh.vol", "mesh.next.vol",
           "fields.pvd", "fields_step*.vtu", "contact_step*.vtu",
           "steps-*", "fig*_step*.png", "wear.png", "pressure.png", "history.png", "contact_maps.png", "regions.png",
           "coefficients.png", "pressure_radius.png", "life.png")
"""The files (and folders) of a run in its output folder (see the reference of the result files)."""


def _remove_leftovers(folder: Path) -> None:
    """Remove the temporary files and folders of dead runs from ``folder`` (held: no live run writes them)."""
    for entry in os.scandir(folder):
        if LEFTOVERS.match(entry.name):
            remove(Path(entry.path))


def clear(folder) -> None:
    """Remove the files of an earlier run from ``folder`` (:data:`OUTPUTS`), before a new run writes there."""
    folder = Path(folder)
    for pattern in OUTPUTS:
        for path in folder.glob(pattern):
            remove(path)


def remove(path: Path) -> None:
    """Remove a file, or a folder with what it holds; a link is removed itself, never followed."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    else:
        path.unlink(missing_ok=True)


def _holder(words: list[str]) -> str:
    if not words:
        return "PID unknown: it is starting"
    pid, host = words[0], " ".join(words[1:])
    return f"PID {pid}" if host in ("", socket.gethostname()) else f"PID {pid} on {host}"


def digest(path) -> str:
    """The SHA-256 of a file (cached by path, size and mtime: a mesh is hashed once per run)."""
    stat = os.stat(path)
    return _digest(str(Path(path).resolve()), stat.st_size, stat.st_mtime_ns)


@lru_cache(maxsize=16)
def _digest(path: str, size: int, mtime: int) -> str:
    with open(path, "rb") as file:
        return hashlib.file_digest(file, "sha256").hexdigest()


def read_arrays(path: Path, key: str) -> dict:
    """Every array of the ``.npz`` file ``path``, or a FolderError (``key``: the argument) saying it is damaged."""
    try:
        with np.load(path) as data:
            return {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as err:
        reason = str(err).split(". ")[0]             # numpy's advice on pickles is not for a damaged file
        raise FolderError(key, f"{path} is damaged ({type(err).__name__}: {reason})") from None


@contextmanager
def replacing(path):
    """``with replacing(path) as tmp:`` write ``tmp``; then it replaces ``path`` in one rename (or vanishes).

    ``tmp`` (``.<stem>.<pid>.<random>.tmp<suffix>`` beside ``path``) is a new empty file, created exclusively (a
    name planted in advance is never used), and the rename replaces whatever ``path`` is, a link too, without
    writing through it.
    """
    path = Path(path)
    while True:
        tmp = path.with_name(f".{path.stem}.{os.getpid()}.{secrets.token_hex(4)}.tmp{path.suffix}")
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o666))
            break
        except FileExistsError:
            continue
    try:
        yield tmp
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    os.replace(tmp, path)
