"""``python -m gearcheck``: the command line."""

import sys

from gearcheck.cli import main

sys.exit(main())
