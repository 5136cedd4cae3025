"""The scenes, studies and CAD part shipped with ngwear (package data in ``ngwear/examples``).

``geometries/`` in a checkout of the repository is this folder, so every shipped scene exists once.  A
scene is named by its file's stem (``paper_strip``); :func:`find` turns such a name into the file.
"""
from __future__ import annotations

from importlib.resources import files
from pathlib import Path

FOLDER = Path(str(files("ngwear") / "examples"))
"""Where the shipped scenes are (``geometries/`` of the repository)."""


def scene_file(name: str) -> Path:
    """The shipped scene ``name`` (a file stem such as ``paper_strip``); ``KeyError`` if there is none."""
    path = FOLDER / f"{name}.toml"
    if not path.is_file():
        raise KeyError(name)
    return path
