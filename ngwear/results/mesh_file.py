"""The run's mesh beside its results: ``mesh.vol``, written so that every file of the folder finds its own mesh.

A result file keeps the SHA-256 of the mesh it was computed on (``mesh_sha256``); :func:`checked_mesh` compares
it before NGSolve reads the file.  A new mesh (a geometry update's) is written as ``mesh.next.vol`` and takes the
name ``mesh.vol`` only once the file that refers to it has been renamed into place (:func:`kept_mesh`): at every
instant — a full disk or a kill between any two writes — each file of the folder refers to a mesh the folder holds.
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path

from .folder import FolderError, digest, replacing

MESH, NEXT = "mesh.vol", "mesh.next.vol"


def checked_mesh(folder: Path, data, dim: int, key: str):
    """The folder's mesh that ``data`` was computed on (its ``mesh_sha256``), else a FolderError.

    ``mesh.vol``, or ``mesh.next.vol`` where a run stopped between writing the file that refers to it and renaming
    it: then it becomes ``mesh.vol`` (the folder is held by the caller).
    """
    from ..model.scene_mesh import load_mesh

    folder = Path(folder)
    path, pending = folder / MESH, folder / NEXT
    if not path.is_file() and not pending.is_file():
        raise FolderError(key, f"{folder} holds no mesh.vol (the mesh its results were computed on)")
    wanted = str(data["mesh_sha256"])
    if pending.is_file() and digest(pending) == wanted:
        os.replace(pending, path)
    elif not path.is_file() or digest(path) != wanted:
        raise FolderError(key, f"{path} is not the mesh its results were computed on (its SHA-256 differs: "
                               "replaced or damaged)")
    return load_mesh(path, dim)


@contextmanager
def kept_mesh(result, folder):
    """``with kept_mesh(result, folder) as sha:`` write the file that refers to the result's mesh by ``sha``.

    The mesh is written unless ``mesh.vol`` is it already: as ``mesh.next.vol``, renamed onto ``mesh.vol`` after the
    block; if the block fails, ``mesh.next.vol`` goes and ``mesh.vol`` stays the mesh of the files written before.
    """
    folder = Path(folder)
    path, pending = folder / MESH, folder / NEXT
    if result.mesh_digest is not None and path.is_file() and digest(path) == result.mesh_digest:
        yield result.mesh_digest
        return
    try:
        with replacing(pending) as tmp:
            result.discretization.mesh.ngmesh.Save(str(tmp))
        sha = digest(pending)
        yield sha
    except BaseException:
        pending.unlink(missing_ok=True)
        raise
    os.replace(pending, path)
    result.mesh_digest = sha


def saved_discretization(scene, folder: Path, data):
    """The discretization of a saved run on the mesh of its folder (None without one)."""
    if not (folder / MESH).is_file() and not (folder / NEXT).is_file():
        return None
    from ..numerics.discrete import Discretization
    return Discretization(scene, checked_mesh(folder, data, scene.dim, "directory"))
