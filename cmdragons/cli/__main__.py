"""``python -m cmdragons.cli``: the ``cmdragons`` command."""

import sys

from cmdragons.cli import main

sys.exit(main())
