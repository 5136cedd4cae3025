"""ngwear: elastic body in frictional contact with a moving rigid foundation, with wear of its soft layer."""
from .model.scene import Scene, SceneError, load_scene
from .results.result import Result, load_result
from .runs.simulate import simulate
from .studies.sweep import sweep

__all__ = ["Result", "Scene", "SceneError", "load_result", "load_scene", "simulate", "sweep"]
__version__ = "0.1.0"
