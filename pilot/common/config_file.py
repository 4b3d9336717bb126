"""Reading a config file: its bytes (bounded, without blocking on a FIFO), its encoding and its YAML, each
problem as one ConfigError line naming the file; pilot/common/config.py builds and checks the options."""

from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Any

import yaml

from .errors import ConfigError

MAX_CONFIG_BYTES = 1_000_000  # a config is a few kilobytes; this bounds what a wrong file can cost


def _read_text(path: Path, where: str) -> str:
    try:  # without blocking: a FIFO would otherwise wait for a writer for ever
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        with open(fd, "rb") as f:
            if not stat.S_ISREG(mode := os.fstat(fd).st_mode):
                kind = "a folder" if stat.S_ISDIR(mode) else "not a regular file (a FIFO, a device or a socket)"
                raise ConfigError(f"{where}: cannot read config: it is {kind}")
            raw = f.read(MAX_CONFIG_BYTES + 1)
    except OSError as exc:
        raise ConfigError(f"{where}: cannot read config: {exc.strerror or exc}") from exc
    if len(raw) > MAX_CONFIG_BYTES:
        raise ConfigError(f"{where}: config larger than {MAX_CONFIG_BYTES:,} bytes: is it the right file?")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")) or raw[:2].count(0) == 1:
        raise ConfigError(f"{where}: the config is saved as UTF-16: save it as UTF-8")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ConfigError(
            f"{where}:{line}: the config is not UTF-8 (byte 0x{raw[exc.start]:02x}, perhaps Latin-1 or "
            "Windows-1252): save it as UTF-8"
        ) from exc


def _yaml_problem(exc: yaml.YAMLError) -> str:
    """A YAML error on one line: line:column: problem."""
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        problem = " ".join(str(x) for x in (exc.context, exc.problem) if x)
        where = f"{mark.line + 1}:{mark.column + 1}: " if mark is not None else ""
        return f"{where}not valid YAML: {' '.join(problem.split())}"
    return f"not valid YAML: {' '.join(str(exc).split())}"


def read_mapping(path: Path, where: str) -> dict[str, Any]:
    """The config file's top-level mapping (empty for an empty file), or one ConfigError line naming ``where``."""
    text = _read_text(path, where)
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(f"{where}:{_yaml_problem(exc)}" if isinstance(exc, yaml.MarkedYAMLError)
                          else f"{where}: {_yaml_problem(exc)}") from exc
    except RecursionError as exc:
        raise ConfigError(f"{where}: not valid YAML: nested too deep for a config") from exc
    except ValueError as exc:  # an integer of thousands of digits, a bad timestamp
        raise ConfigError(f"{where}: not valid YAML: {' '.join(str(exc).split())[:160]}") from exc
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigError(f"{where}: the top level must be a mapping of options")
    return data
