"""`python -m pinmech ...` runs the CLI."""

import sys

from pinmech.cli import main

sys.exit(main())
