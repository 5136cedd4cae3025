"""ngwear: elastic body in frictional contact with a moving rigid foundation, with wear of its soft layer."""
from .result import Result, load_result
from .scene import Scene, SceneError, load_scene
from .simulate import simulate

__all__ = ["Result", "Scene", "SceneError", "load_result", "load_scene", "simulate"]
__version__ = "0.1.0"
