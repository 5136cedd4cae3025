"""Sphinx-Gallery scraper of the pictures an example writes as files.

ngwear draws into PNG files (``ngwear run`` writes them beside the results), not into open matplotlib
figures.  An example writes into ``out/<name>/`` of its working folder, as ``ngwear run`` does; after each
code block this scraper takes the PNG files written there since the block began, in the order they were
written, and puts them under the block.  :func:`reset` (a ``reset_modules`` hook) starts the clock of each
example, so pictures of an earlier build are never taken for new ones.
"""
from __future__ import annotations

import shutil
import time
from pathlib import Path

from sphinx_gallery.scrapers import figure_rst

_since = {"ns": time.time_ns()}


def reset(gallery_conf, fname, when=None) -> None:
    """Before (and after) each example: only files written from now on are its pictures."""
    _since["ns"] = time.time_ns()


def png_files(block, block_vars, gallery_conf) -> str:
    """The reST of the PNG files written into ``out/`` during the last code block."""
    out = Path.cwd() / "out"
    start = _since["ns"]
    _since["ns"] = time.time_ns()
    new = sorted((p.stat().st_mtime_ns, p) for p in out.rglob("*.png") if p.stat().st_mtime_ns >= start) \
        if out.is_dir() else []
    targets = []
    for _, path in new:
        target = Path(next(block_vars["image_path_iterator"]))
        shutil.copyfile(path, target)
        targets.append(str(target))
    return figure_rst(targets, gallery_conf["src_dir"]) if targets else ""
