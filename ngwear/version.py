"""The version of ngwear, in one place: ``pyproject.toml`` reads it (dynamic), ``ngwear --version`` prints it."""
__version__ = "0.1.0"
