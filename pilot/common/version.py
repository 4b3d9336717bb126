"""The pilot's version, reported by ``pilot --version`` with the spec's fingerprint."""

__version__ = "0.1.0"
