"""The command line's shell: the scene a command's SCENE and --set give, and the log lines."""
from __future__ import annotations

import argparse
import logging
import sys

from ..model.scene import SceneError, load_scene, parse_override

STAGES = logging.getLogger("ngwear.progress")
"""Where the stages of a command are told (shown unless --quiet; see :mod:`ngwear.runs.progress`)."""


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line (the command, what is wrong, where help is), exit 2."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: {message} (see `{self.prog} --help`)\n")


def scene_of(args, required: bool = True):
    """The scene of SCENE and --set; a --set item without '=' stands for SCENE (options in any order)."""
    settings = [item for item in args.set if "=" in item]
    strays = [item for item in args.set if "=" not in item]
    if strays and args.scene is None and len(strays) == 1:
        args.scene = strays.pop()
    if strays:
        parse_override(strays[0])                    # the one-line message for an item without '='
    if args.scene is None:
        if required:
            raise SceneError("scene file: missing (give SCENE: a scene file, or a shipped scene such as paper_strip)")
        return None, settings
    return load_scene(args.scene, dict(parse_override(item) for item in settings)), settings



class _Stderr(logging.StreamHandler):
    """Log lines on whatever ``sys.stderr`` is when they are written (pytest and Jupyter replace it)."""

    stream = property(lambda self: sys.stderr, lambda self, _: None)


def log_lines(quiet: bool, verbose: bool) -> None:
    """Log lines on stderr as ``ngwear: …``: ngwear's warnings, its progress lines unless ``quiet``; ``verbose``: all.

    Other libraries' warnings and errors are shown (the app server's refusals among them), except Dask's below
    ERROR (its INFO lines and the notes on connections closed at the end of a study), which only ``verbose`` shows.
    """
    root = logging.getLogger()
    for handler in [h for h in root.handlers if h.get_name() == "ngwear"]:
        root.removeHandler(handler)
    handler = _Stderr()
    handler.set_name("ngwear")
    handler.setFormatter(logging.Formatter("ngwear: %(message)s"))
    if not verbose:
        handler.addFilter(_shown)
    root.addHandler(handler)
    logging.getLogger("ngwear").setLevel(logging.DEBUG if verbose else logging.NOTSET)
    logging.getLogger("ngwear.progress").setLevel(logging.WARNING if quiet else logging.INFO)


def _shown(record: logging.LogRecord) -> bool:
    """Without --verbose: ngwear's lines, errors, and other libraries' warnings but Dask's."""
    library = record.name.split(".")[0]
    return (library == "ngwear" or record.levelno >= logging.ERROR
            or (record.levelno >= logging.WARNING and library != "distributed"))
