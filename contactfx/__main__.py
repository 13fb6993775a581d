"""Allow `python -m contactfx`."""

import sys

from .cli import main

sys.exit(main())
