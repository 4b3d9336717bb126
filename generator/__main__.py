"""`python -m generator`: regenerate every target from the spec."""

import sys

from generator.cli import main

sys.exit(main())
