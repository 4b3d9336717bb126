"""`python -m generator`: regenerate every target from the spec."""

import sys

from .cli import main

sys.exit(main())
