"""The explorer's old home: it lives in :mod:`ngwear.views.explore`; ``ngwear.Explorer`` is its public name."""
from .views.explore import Explorer, RunError

__all__ = ["Explorer", "RunError"]
