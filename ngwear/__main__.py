"""``python -m ngwear``: the command line, as the ``ngwear`` script (see :mod:`ngwear.cli`)."""
import sys

from .cli import main

sys.exit(main())
