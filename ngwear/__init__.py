"""ngwear: elastic body in frictional contact with a moving rigid foundation, with wear of its soft layer.

The public API is what this module exports (``__all__``): scenes (:class:`Scene`, :func:`load_scene`),
runs (:func:`simulate`, :class:`Result`, :func:`load_result`, :class:`Discretization` to reuse a mesh and
its factorisation across runs), the explorer (:class:`Explorer`, imported on first use: it needs pyvista)
and parameter studies (:func:`sweep`, :func:`load_study`).  Everything else is internal.
"""
from .model.scene import Scene, SceneError, load_scene
from .numerics.discrete import Discretization
from .results.result import Result, load_result
from .runs.simulate import simulate
from .studies.study import Study, StudyError, load_study
from .studies.sweep import sweep
from .version import __version__ as __version__

__all__ = ["Discretization", "Explorer", "Result", "Scene", "SceneError", "Study", "StudyError", "load_result",
           "load_scene", "load_study", "simulate", "sweep"]


def __getattr__(name: str):
    """``ngwear.Explorer`` on first use (the explorer draws with pyvista, which ``import ngwear`` does not load)."""
    if name == "Explorer":
        from .views.explore import Explorer
        return Explorer
    raise AttributeError(f"module 'ngwear' has no attribute {name!r}")
