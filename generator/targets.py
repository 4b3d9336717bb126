"""The generated targets. Adding one means a template folder under templates/ and one line here.

The do-not-edit header of each generated file is written in the comment syntax of that file's own format,
decided per file (a target mixes formats: the Arduino library has C++ next to a properties file)."""

from __future__ import annotations

from pathlib import PurePosixPath

from .records import record


@record
class Target:
    name: str  # the folder of templates under generator/templates/
    out_dir: str  # where its files go, relative to the output folder ("" for the top)
    own_header: bool = False  # its templates print the do-not-edit header themselves
    # "html": every printed value is HTML-escaped (& < >) unless a filter already made it safe (filters.Safe)
    escape: str = ""


TARGETS: tuple[Target, ...] = (
    Target("python", "python"),
    Target("arduino", "arduino"),
    Target("docs", "docs", escape="html"),
    Target("vectors", ""),
    Target("contract", ""),  # what a peer relies on: the previous version for the breaking-change check
    Target("ardupilot", "ardupilot"),
    Target("rust", "rust", own_header=True),  # each template prints the header in its file's own syntax
    Target("vectors", "rust/tests"),  # the crate's own copy: its packaged tests run without the repository
    Target("c", "c"),
    Target("typescript", "typescript", own_header=True),  # .ts, .mjs, .json, .html: each template prints its header
)

# How a file carries the header: a line-comment prefix, "<!--" (one block comment), or "json" (no comments:
# the template prints the header as its first member). By whole file name first, then by suffix.
COMMENT_BY_NAME = {
    "keywords.txt": "#",  # the Arduino IDE skips lines starting with '#'
    "py.typed": "#",
    "LICENSE": "",  # no header: license checkers (crates.io, licensee, npm) read the text as written
}
COMMENT_BY_SUFFIX = {
    ".properties": "#",  # Arduino's library.properties: '#' is the only comment its parsers accept
    ".py": "#",
    ".toml": "#",
    ".parm": "#",  # ArduPilot parameter files (Mission Planner, MAVProxy)
    ".params": "#",  # QGroundControl's parameter files: it skips lines that start with '#'
    ".h": "//",
    ".hpp": "//",
    ".c": "//",
    ".cpp": "//",
    ".ino": "//",
    ".ts": "//",
    ".js": "//",
    ".rs": "//",
    ".md": "<!--",
    ".html": "<!--",
    ".svg": "<!--",  # XML allows a comment before the root element
    ".json": "json",
    ".lock": "#",  # Cargo.lock
}


def comment_style(path: str) -> str:
    """The header style of the generated file at `path`; a format nobody taught us is an error, not a guess."""
    p = PurePosixPath(path)
    style = COMMENT_BY_NAME[p.name] if p.name in COMMENT_BY_NAME else COMMENT_BY_SUFFIX.get(p.suffix)
    if style is None:
        raise ValueError(f"no comment syntax known for generated file '{path}': add its name or suffix to "
                         "COMMENT_BY_NAME / COMMENT_BY_SUFFIX in generator/targets.py")
    return style
