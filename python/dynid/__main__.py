"""``python -m dynid``: the ``dynid`` command (an environment without its script on PATH)."""

import sys

from .cli.main import main

sys.exit(main())
