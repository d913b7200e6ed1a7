"""``python -m xairl.cli``: the ``xairl`` command."""

import sys

from . import main

sys.exit(main())
