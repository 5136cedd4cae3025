"""ngwear: elastic body in frictional contact with a moving rigid foundation, with wear of its soft layer.

The public API is what this module exports (``__all__``): scenes (:class:`Scene`, :func:`load_scene`),
runs (:func:`simulate`, :class:`Result`, :func:`load_result`, :class:`Discretization` to reuse a mesh and
its factorisation across runs), the explorer (:class:`Explorer`: it needs pyvista) and parameter studies
(:func:`sweep`, :func:`load_study`).  Everything else is internal.

``import ngwear`` itself loads nothing but this module: the names load on first use (NGSolve and NumPy with the
first of them, pyvista with the explorer), so that the ``ngwear`` command handles a signal from its first instant.
"""
from importlib import import_module

from .version import __version__ as __version__

__all__ = ["Discretization", "Explorer", "Result", "Scene", "SceneError", "Study", "StudyError", "load_result",
           "load_scene", "load_study", "simulate", "sweep"]

_WHERE = {"Scene": "model.scene", "SceneError": "model.scene", "load_scene": "model.scene",
          "Discretization": "numerics.discrete", "Result": "results.result", "load_result": "results.result",
          "simulate": "runs.simulate", "Study": "studies.study", "StudyError": "studies.study",
          "load_study": "studies.study", "sweep": "studies.sweep", "Explorer": "views.explore"}
"""The module of each exported name."""
_CORE = ("model.scene", "numerics.discrete", "results.result", "runs.simulate", "studies.study", "studies.sweep")
"""What the first use of a name (or of a subpackage) loads: the whole package but the explorer's drawing."""


def __getattr__(name: str):
    """An exported name, or a subpackage (``ngwear.results``), loaded on first use with the core of the package."""
    if name in _WHERE or name in ("model", "numerics", "results", "runs", "studies", "views", "child", "cli"):
        for module in _CORE:
            import_module(f".{module}", __name__)
        if name in _WHERE:
            value = getattr(import_module(f".{_WHERE[name]}", __name__), name)
        else:
            value = import_module(f".{name}", __name__)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ngwear' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *__all__])
