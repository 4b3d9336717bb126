"""The README's Python example runs as written: each line's result is what its comment says."""

from __future__ import annotations

import re

import drone_protocol as dp
import protocol_harness as h

README = h.ROOT / "README.md"


def example_lines() -> list[tuple[str, str]]:
    text = README.read_text(encoding="utf-8")
    block = text.split("### Using the Python module", 1)[1]
    (code,) = re.findall(r"```python\n(.*?)```", block, re.S)[:1]
    lines = []
    for line in code.splitlines():
        if not line.strip() or line.startswith("import "):
            continue
        expression, _, comment = line.partition("  # ")
        lines.append((expression.strip(), comment.strip()))
    return lines


def test_the_readme_python_example_prints_what_its_comments_say() -> None:
    lines = example_lines()
    assert len(lines) >= 5, "the README's Python example lost its lines"
    for expression, comment in lines:
        error = re.match(r"(\w+Error): (.*)", comment)
        if error:
            try:
                eval(expression, {"dp": dp})  # the README's own code, nothing else
            except dp.ProtocolError as exc:
                assert (type(exc).__name__, str(exc)) == (error.group(1), error.group(2)), expression
                continue
            raise AssertionError(f"{expression} did not raise {error.group(1)}")
        result = eval(expression, {"dp": dp})
        if comment.startswith("b'"):
            assert repr(result) == comment.split(" (")[0], (expression, result)
        elif comment.startswith("<"):
            assert repr(result) == comment[:comment.index(">") + 1], (expression, result)
        elif comment.startswith(("True", "False")):
            assert repr(result) == comment.split(":")[0], (expression, result)
        else:
            assert comment.startswith("the two commands"), (expression, comment)
            assert [c.name for c in result] == [dp.CommandName.MOVE_FORWARD, dp.CommandName.LASER_ON]
