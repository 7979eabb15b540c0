"""``python -m mechdyn``: the same command line as the ``mechdyn`` script."""

import sys

from .cli import main

sys.exit(main())
