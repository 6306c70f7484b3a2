"""`python -m snell.usd`: the snell-usd command (snell.usd.cli)."""

import sys

from .cli import main

sys.exit(main())
