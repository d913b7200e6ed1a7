"""``python -m xairl.cli``: the ``xairl`` command."""

import sys

from xairl.cli import main

sys.exit(main())
