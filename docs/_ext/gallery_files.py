"""Sphinx-Gallery scraper of the pictures an example writes as files.

ngwear draws into PNG files (``ngwear run`` writes them beside the results), not into open matplotlib
figures.  An example writes into ``out/<name>/`` of its working folder, as ``ngwear run`` does; after each
code block this scraper takes the PNG files written there since the block began, in the order they were
written, and puts them under the block.  :func:`reset` (a ``reset_modules`` hook) starts the clock of each
example, so pictures of an earlier build are never taken for new ones.

With ``NGWEAR_DEMO_CHECKS`` naming a file (``tests/test_demos.py`` sets it), :func:`reset` runs each example's check
(``tests/demo_checks.py``) on the example's variables once it has run and appends the record to that file as a line
of JSON: the tests assert the numbers of the build's own run, and no demo runs twice.

An example's thumbnail is its first picture.  When that is one of ngwear's pictures of the part (``fig1_step025.png``,
``regions.png``), :func:`thumbnails` makes it anew from the picture's frame (:data:`ngwear.views.render.FRAME`): the
part without the colour bars, the caption and the margins around them.
"""
from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

from PIL import Image
from sphinx_gallery.scrapers import figure_rst
from sphinx_gallery.utils import scale_image

_since = {"ns": time.time_ns()}
PICTURES = re.compile(r"^(fig\d+_step\d+|regions)\.png$")
"""The file names of ngwear's pictures of the part (:func:`ngwear.views.pictures.write_pictures`)."""
_framed: set[Path] = set()
CHECKS = os.environ.get("NGWEAR_DEMO_CHECKS")
"""The file the examples' checks are appended to (unset: no checks)."""
_example: dict = {}
"""The running example's variables, folder and number of pictures (what its check needs)."""


def reset(gallery_conf, fname, when=None) -> None:
    """Before and after each example: only files written from now on are its pictures; after it, its check."""
    _since["ns"] = time.time_ns()
    if when == "after" and CHECKS:
        _check(Path(fname).stem)
    _example.clear()


def _check(name: str) -> None:
    """Append the check of example ``name`` (run in its folder, on its variables) to :data:`CHECKS`."""
    tests = str(Path(__file__).resolve().parents[2] / "tests")
    if tests not in sys.path:
        sys.path.insert(0, tests)
    import demo_checks

    with contextlib.chdir(_example["folder"]):
        record = demo_checks.record(name, _example["variables"])
    with open(CHECKS, "a") as file:
        file.write(json.dumps({**record, "pictures": _example["pictures"]}) + "\n")


def png_files(block, block_vars, gallery_conf) -> str:
    """The reST of the PNG files written into ``out/`` during the last code block."""
    out = Path.cwd() / "out"
    _example.update(variables=block_vars["example_globals"], folder=Path.cwd())
    start = _since["ns"]
    _since["ns"] = time.time_ns()
    new = sorted((p.stat().st_mtime_ns, p) for p in out.rglob("*.png") if p.stat().st_mtime_ns >= start) \
        if out.is_dir() else []
    targets = []
    for _, path in new:
        target = Path(next(block_vars["image_path_iterator"]))
        shutil.copyfile(path, target)
        targets.append(str(target))
        if PICTURES.match(path.name):
            _framed.add(target)
    _example["pictures"] = _example.get("pictures", 0) + len(targets)
    return figure_rst(targets, gallery_conf["src_dir"]) if targets else ""


def thumbnails(app) -> None:
    """After Sphinx-Gallery made them (``builder-inited``): thumbnails of ngwear's pictures show the picture's frame."""
    from ngwear.views.camera import FRAME

    width, height = app.config.sphinx_gallery_conf["thumbnail_size"]
    for picture in sorted(_framed):
        if not picture.stem.endswith("_001"):      # the thumbnail is an example's first picture
            continue
        thumb = picture.parent / "thumb" / f"{picture.stem.removesuffix('_001')}_thumb{picture.suffix}"
        with Image.open(picture) as image, tempfile.TemporaryDirectory() as folder:
            w, h = image.size
            left, right, bottom, top = FRAME
            image.crop((round(left * w), round((1 - top) * h), round(right * w), round((1 - bottom) * h))).save(
                Path(folder) / "frame.png")
            scale_image(Path(folder) / "frame.png", thumb, width, height)
