"""``python -m attitude``: the command line (``attitude.cli``)."""

import sys

from attitude.cli import main

sys.exit(main())
