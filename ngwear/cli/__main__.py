"""``python -m ngwear.cli COMMAND …``: the command line (as ``ngwear`` and ``python -m ngwear``)."""
import sys

from . import main

sys.exit(main())
