"""Meshing a scene's body with Netgen, and the on-disk cache of meshes.

The shapes come from the registry of part kinds (:mod:`ngwear.model.shapes`, :mod:`ngwear.model.user_parts`); the
body is the region ``body``, its contact face/edge ``contact``.  The soft layer is not meshed: it lives on
the contact points (its compression and wear are nodal) and pictures draw it by offsetting Γ_C along ν.
``mesh.grading`` (Netgen's, default 0.3) slows the growth of the elements away from refined faces and from the
refined zone of Γ_C (:mod:`ngwear.model.zone`).  Meshes
are cached on disk by a hash of the keys that declare they invalidate the mesh (``$NGWEAR_CACHE`` or
``~/.cache/ngwear``).
"""
from __future__ import annotations

import hashlib
import os
import threading

import netgen.meshing
import ngsolve as ngs
import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .keys import Level, SceneError
from .kinds import KINDS
from .netgen_meshing import Stopped, check_size, generate, part
from .user_parts import cache_dir, read_mesh

CACHE_VERSION = 5


def mesh_key(scene) -> str:
    """Hash of everything the mesh depends on: the keys at :attr:`Level.MESH`, a part file by its content alone.

    A project moved or cloned elsewhere finds its meshes: neither the file's path nor its mtime is in the key.
    """
    spec = scene.signature(Level.MESH, by_content=True)
    return hashlib.sha256(f"{CACHE_VERSION}:{spec}".encode()).hexdigest()[:16]


def _check_complete(mesh: ngs.Mesh, measure: float) -> None:
    """Netgen can leave faces unmeshed with only a printed warning: compare the meshed measure.

    Straight-sided elements under curved faces lose a few per cent of the measure at a coarse maxh
    (a cylinder of radius 2 maxh: 3 %); a partial meshing loses whole regions.
    """
    meshed = ngs.Integrate(ngs.CF(1.0), mesh)
    if abs(meshed - measure) > 0.1 * measure:
        raise SceneError(f"mesh: Netgen meshed only {meshed / measure:.1%} of the geometry; "
                         "raise mesh.grading or mesh.contact_maxh, or change mesh.maxh")


def build_mesh(scene, use_cache: bool = True, stop: threading.Event | None = None) -> ngs.Mesh:
    """Mesh the scene's body, reusing the on-disk cache when possible (a mesh file is read as it is).

    A new mesh is returned as read back from its file: the file stores the vertices to the last bit
    that reading restores, so a first run, a cached run and a run resumed from its output folder's
    ``mesh.vol`` compute on the same numbers.  A part file's mesh must hang together where it is not held
    (:func:`_check_held`).  Before Netgen runs, the part's elements are estimated and refused beyond
    ``mesh.max_elements``; a large mesh is made in a child process that a set ``stop`` ends at once
    (:mod:`ngwear.model.netgen_meshing`: :class:`~ngwear.model.netgen_meshing.Stopped`).
    """
    mesh = _build_mesh(scene, use_cache, stop)
    if scene.geometry.file is not None:
        _check_held(mesh, scene)
    return mesh


def _check_held(mesh: ngs.Mesh, scene) -> None:
    """Refuse a part that falls apart into pieces of which one is held by neither geometry.dirichlet nor the plate.

    Such a piece (a solid that does not share faces with the others) floats: the stiffness is singular.
    """
    elements = (mesh.ngmesh.Elements3D() if mesh.dim == 3 else mesh.ngmesh.Elements2D()).NumPy()
    nodes = elements["nodes"]
    ne, nv = len(nodes), mesh.nv
    rows, cols = np.repeat(np.arange(ne), nodes.shape[1]), nodes.ravel() - 1
    used = cols >= 0
    graph = sp.coo_matrix((np.ones(used.sum()), (rows[used], ne + cols[used])), shape=(ne + nv,) * 2)
    count, labels = connected_components(graph, directed=False)
    if count == 1:
        return
    held = set(scene.geometry.dirichlet) | ({scene.loads.plate.boundary} if scene.loads.plate else set())
    held_labels = {labels[ne + v.nr] for el in mesh.Elements(ngs.BND) if el.mat in held for v in el.vertices}
    floating = ~np.isin(labels[:ne], list(held_labels))
    if floating.any():
        names = mesh.GetMaterials()
        regions = sorted({names[index - 1] for index in elements["index"][floating]})
        raise SceneError(f"geometry.file: the part falls apart: region {' and '.join(regions)} is held by neither "
                         "geometry.dirichlet nor loads.plate and would float (its solids must share faces with the "
                         "rest)")


def _build_mesh(scene, use_cache: bool, stop: threading.Event | None) -> ngs.Mesh:
    g = scene.geometry
    kind = KINDS[g.kind]
    if kind.build is None:
        return ngs.Mesh(read_mesh(g.file))
    path = cache_dir() / "meshes" / f"{mesh_key(scene)}.vol"
    if use_cache and path.is_file():
        return load_mesh(path, g.dim)
    name = "geometry.file" if g.file is not None else "geometry.size"
    try:
        check_size(scene, kind.build(g, scene.mesh))        # Γ_C's faces refined all over: an upper bound
        shape = part(g, scene.mesh)
    except Exception as err:  # noqa: BLE001 - OpenCASCADE raises its own types, with their message
        if isinstance(err, SceneError):
            raise
        raise SceneError(f"{name}: Netgen cannot build or mesh this part ({_reason(err)}); change its size or "
                         "mesh.maxh") from None
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp.vol")
    try:
        try:
            generate(scene, shape, tmp, stop)
        except (Stopped, SceneError):
            raise
        except Exception as err:  # noqa: BLE001 - Netgen raises its own types, with their message
            raise SceneError(f"{name}: Netgen cannot build or mesh this part ({_reason(err)}); change its size or "
                             "mesh.maxh") from None
        mesh = load_mesh(tmp, g.dim)
        _check_complete(mesh, sum(part.mass for part in (shape.faces if g.dim == 2 else shape.solids)))
        if use_cache:
            tmp.replace(path)
        return mesh
    finally:
        tmp.unlink(missing_ok=True)


def _reason(err: Exception) -> str:
    return str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__


def load_mesh(path, dim: int) -> ngs.Mesh:
    """A Netgen ``.vol`` mesh file as an NGSolve mesh."""
    ngmesh = netgen.meshing.Mesh(dim=dim)
    ngmesh.Load(str(path))
    return ngs.Mesh(ngmesh)
