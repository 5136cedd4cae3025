"""Where a result comes from: the versions that computed it and the identity of its scene.

``{"ngwear": …, "ngsolve": …, "python": …, "scene_sha256": …}``, the SHA-256 of the scene's canonical JSON (its
:meth:`~ngwear.model.scene.Scene.to_dict`, keys sorted, no spaces, UTF-8): two runs of equal scenes share it, and
``scene.json`` beside a result gives it again.  ``summary.json``, ``result.npz`` (as JSON) and each row of a study's
table (:func:`columns`: ``ngwear_version``, ``ngsolve_version``, ``python_version``, ``scene_sha256``) record it.
"""
from __future__ import annotations

import hashlib
import json
import platform

import ngsolve

from ..version import __version__


def provenance(scene) -> dict[str, str]:
    """The ngwear, NGSolve and Python versions of this process and the hash of ``scene``."""
    return {"ngwear": __version__, "ngsolve": ngsolve.__version__, "python": platform.python_version(),
            "scene_sha256": scene_hash(scene)}


COLUMNS = ("ngwear_version", "ngsolve_version", "python_version", "scene_sha256")
"""The provenance's columns in a study's table."""


def columns(scene) -> dict[str, str]:
    """:func:`provenance` as a study table's :data:`COLUMNS`."""
    return dict(zip(COLUMNS, provenance(scene).values()))


def scene_hash(scene) -> str:
    """SHA-256 of the scene's canonical JSON."""
    return hashlib.sha256(canonical(scene.to_dict()).encode()).hexdigest()


def canonical(data: dict) -> str:
    """JSON with sorted keys and no spaces (the text :func:`scene_hash` hashes)."""
    return json.dumps(data, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
