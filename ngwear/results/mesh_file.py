"""The run's mesh beside its results: ``mesh.vol``, written atomically, trusted only once it is seen to be theirs.

A result file keeps the SHA-256 of the mesh it was computed on (``mesh_sha256``); :func:`checked_mesh` compares
it before NGSolve reads the file.
"""
from __future__ import annotations

from pathlib import Path

from .folder import FolderError, digest, replacing


def checked_mesh(folder: Path, data, dim: int, key: str):
    """The folder's ``mesh.vol`` once it is seen to be the mesh ``data`` was computed on (else a FolderError).

    Its SHA-256 must be ``data``'s ``mesh_sha256`` (which its reader checked is there).
    """
    from ..model.scene_mesh import load_mesh

    path = Path(folder) / "mesh.vol"
    if not path.is_file():
        raise FolderError(key, f"{folder} holds no mesh.vol (the mesh its results were computed on)")
    if digest(path) != str(data["mesh_sha256"]):
        raise FolderError(key, f"{path} is not the mesh its results were computed on (its SHA-256 differs: "
                               "replaced or damaged)")
    return load_mesh(path, dim)


def keep_mesh(result, folder) -> str:
    """Write the result's mesh as ``mesh.vol`` in ``folder`` unless it is there already; its SHA-256."""
    path = Path(folder) / "mesh.vol"
    if result.mesh_digest is None or not path.is_file() or digest(path) != result.mesh_digest:
        save_mesh(result.discretization.mesh, Path(folder))
        result.mesh_digest = digest(path)
    return result.mesh_digest


def save_mesh(mesh, folder: Path) -> Path:
    """The run's mesh as ``mesh.vol`` in ``folder`` (atomically); the mesh a resumed run reads."""
    with replacing(Path(folder) / "mesh.vol") as tmp:
        mesh.ngmesh.Save(str(tmp))
    return Path(folder) / "mesh.vol"


def saved_discretization(scene, folder: Path, data):
    """The discretization of a saved run on the mesh of its folder (None without one)."""
    if not (folder / "mesh.vol").is_file():
        return None
    from ..numerics.discrete import Discretization
    return Discretization(scene, checked_mesh(folder, data, scene.dim, "directory"))
