"""The scenes, studies and CAD part shipped with ngwear (package data in ``ngwear/examples``).

``geometries/`` in a checkout of the repository is this folder, so every shipped scene exists once.  A
scene is named by its file's stem (``paper_strip``); :func:`scene_file` turns such a name into the file
(:func:`find`: a file, else a name),
:func:`title` gives its one-line description (the first comment line of the file) and :func:`copy` copies
the whole folder (scenes, the CAD part they read, studies, the JSON Schema) to start from.
"""
from __future__ import annotations

import shutil
from importlib.resources import files
from pathlib import Path

from .keys import SceneError

FOLDER = Path(str(files("ngwear") / "examples"))
"""Where the shipped scenes are (``geometries/`` of the repository)."""


def names() -> list[str]:
    """The shipped scenes' names (file stems), sorted."""
    return sorted(path.stem for path in FOLDER.glob("*.toml"))


def scene_file(name: str) -> Path:
    """The shipped scene ``name`` (a file stem such as ``paper_strip``); ``KeyError`` if there is none."""
    path = FOLDER / f"{name}.toml"
    if not path.is_file():
        raise KeyError(name)
    return path


def find(scene) -> Path:
    """The scene file ``scene`` names: itself where it is a file, else the shipped scene of that name.

    Raises
    ------
    SceneError
        ``scene`` is neither a file nor a shipped scene's name (one line naming the shipped ones).
    """
    path = Path(scene)
    if path.is_file():
        return path
    bare = not path.suffix and len(path.parts) == 1
    if path.exists() and not (bare and str(scene) in names()):
        raise SceneError(f"scene file: {path} is not a regular file (a scene TOML file)")
    if not bare:
        raise SceneError(f"scene file: {path} does not exist")
    try:
        return scene_file(str(scene))
    except KeyError:
        raise SceneError(f"scene file: {scene!r} is neither a file nor a shipped scene (shipped: "
                         f"{', '.join(names())}; see `ngwear examples`)") from None


def title(name: str) -> str:
    """The first comment line of the shipped scene ``name`` (after ``#:schema``): what the scene is, in one line."""
    for line in scene_file(name).read_text(encoding="utf-8").splitlines():
        if line.startswith("#") and not line.startswith("#:"):
            return line.lstrip("#").strip()
    return ""


def shipped_files() -> list[Path]:
    """Every shipped file, relative to :data:`FOLDER`: scenes, the CAD part, studies and ``scene.schema.json``."""
    return sorted(path.relative_to(FOLDER) for path in FOLDER.rglob("*")
                  if path.is_file() and "__pycache__" not in path.parts)


def copy(folder) -> list[Path]:
    """Copy every shipped file into ``folder`` (created), keeping the layout that the scenes' relative paths need.

    Parameters
    ----------
    folder : path
        Where to copy to.

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    FileExistsError
        A file of that name is in ``folder`` already; nothing is written then.
    """
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise FileExistsError(f"{folder} exists and is not a folder: nothing copied; copy into a new or empty folder")
    targets = [(FOLDER / name, folder / name) for name in shipped_files()]
    existing = [target for _, target in targets if target.exists()]
    if existing:
        more = f" (and {len(existing) - 1} more of the shipped files)" if len(existing) > 1 else ""
        raise FileExistsError(f"{existing[0]} exists{more}: nothing copied; copy into a new or empty folder")
    for source, target in targets:
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(source, target)
    return [target for _, target in targets]
