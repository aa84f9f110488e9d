"""``python -m gearwear.cli``: the same as the ``gearwear`` console script."""

import sys

from gearwear.cli import main

sys.exit(main())
