"""``python -m attitude``: the command line (``attitude.cli.main``)."""

import sys

from attitude.cli.main import main

sys.exit(main())
