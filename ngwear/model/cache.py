"""Where ngwear keeps what it computed once: meshes and the parts given in Python (``$NGWEAR_CACHE``)."""
from __future__ import annotations

import os
from pathlib import Path


def cache_dir() -> Path:
    """``$NGWEAR_CACHE``, or ``~/.cache/ngwear``."""
    return Path(os.environ.get("NGWEAR_CACHE", Path.home() / ".cache" / "ngwear"))
