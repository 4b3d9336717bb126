"""Generate the drone protocol's code and docs from one YAML spec."""

__version__ = "0.1.0"
