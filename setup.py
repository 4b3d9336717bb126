"""The project's packages, installed under one namespace: the repo's ``generator/`` and ``pilot/`` folders become
``drone_protocol_tools.generator`` and ``drone_protocol_tools.pilot`` (their imports are relative, so the same
code runs as ``python -m generator`` / ``python -m pilot`` in the repo). Template folders are listed too, as
data-only packages, so setuptools ships them without warnings. Everything else is in pyproject.toml."""

from setuptools import find_namespace_packages, setup

NAMESPACE = "drone_protocol_tools"
found = [p for p in find_namespace_packages(include=["generator", "generator.*", "pilot", "pilot.*"])
         if all(part.isidentifier() for part in p.split("."))]

setup(
    packages=[f"{NAMESPACE}.{p}" for p in found],
    package_dir={f"{NAMESPACE}.{p}": p.replace(".", "/") for p in found},
    package_data={f"{NAMESPACE}.{p}": ["py.typed", "*.j2", "**/*.j2", "*.html"] for p in found},
)
