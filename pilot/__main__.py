"""``python -m pilot``."""

from __future__ import annotations

import sys

from .link.protocol_needs import protocol_problem

if __name__ == "__main__":
    try:
        from .app.cli import main
    except AttributeError:  # a module of the pilot read, as it was imported, a protocol name the spec lost
        if (problem := protocol_problem()) is None:
            raise
        print(f"pilot: error: {problem}", file=sys.stderr)
        sys.exit(2)
    sys.exit(main())
