"""Templates precompiled to Python (issue 54, a cold run): the committed set matches the templates, a precompiled
file is used only for the very source and Jinja it was made from, `--check` reports a set out of date and
`python -m generator` refreshes it, and the files rendered are the same either way."""

from __future__ import annotations

import shutil
from pathlib import Path

import jinja2
import pytest

from generator import cli, precompiled
from generator.build import load_spec
from generator.precompiled import PrecompiledLoader, notes, problems, refresh
from generator.render import environments, render_all

REPO = Path(__file__).resolve().parents[2]


def test_the_committed_precompiled_templates_match_the_templates() -> None:
    assert problems(environments(), str) == []


def test_precompiled_and_compiled_templates_render_the_same_files(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = load_spec(REPO / "spec" / "drone.yaml")
    envs = environments()
    fast = render_all(spec, envs)
    assert sum(len(env.loader.current) for env in envs.values() if isinstance(env.loader, PrecompiledLoader)) > 80
    monkeypatch.setenv(precompiled.NO_PRECOMPILED, "1")
    compiled_envs = environments()
    assert render_all(spec, compiled_envs) == fast
    assert all(not env.loader.current for env in compiled_envs.values() if isinstance(env.loader, PrecompiledLoader))


@pytest.fixture
def folders(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    templates, compiled = tmp_path / "templates", tmp_path / "precompiled"
    (templates / "t" / "sub").mkdir(parents=True)
    (templates / "t" / "sub" / "a.txt.j2").write_text("hello {{ who }}", encoding="utf-8")
    monkeypatch.setattr(precompiled, "TEMPLATES", templates)
    monkeypatch.setattr(precompiled, "PRECOMPILED", compiled)
    return templates / "t" / "sub" / "a.txt.j2", compiled / "t" / "sub" / "a.txt.pyj"


def _render() -> str:
    env = jinja2.Environment(loader=PrecompiledLoader("t", "options"))
    return env.get_template("sub/a.txt.j2").render(who="world")


def _envs() -> dict[str, jinja2.Environment]:
    return {"t": jinja2.Environment(loader=PrecompiledLoader("t", "options"))}


def test_a_precompiled_file_is_used_for_its_own_source_only(folders: tuple[Path, Path]) -> None:
    template, compiled = folders
    assert problems(_envs(), str) == [f"missing: {compiled} (the precompiled t/sub/a.txt.j2; run "
                                      "`python -m generator`)"]
    assert refresh(_envs()) == [compiled]
    assert problems(_envs(), str) == [] and refresh(_envs()) == []
    compiled.write_text(compiled.read_text(encoding="utf-8").replace("hello ", "HELLO "), encoding="utf-8")
    assert _render() == "HELLO world"  # the precompiled code is what runs
    template.write_text("bye {{ who }}", encoding="utf-8")
    assert _render() == "bye world"  # an edited template: its old precompiled code is never used
    assert problems(_envs(), str) == [f"stale: {compiled} (compiled from another t/sub/a.txt.j2; run "
                                      "`python -m generator`)"]
    assert refresh(_envs()) == [compiled] and problems(_envs(), str) == []
    assert "bye " in compiled.read_text(encoding="utf-8") and _render() == "bye world"


def test_a_file_made_by_another_jinja_is_not_used_and_only_noted(folders: tuple[Path, Path]) -> None:
    _, compiled = folders
    refresh(_envs())
    text = compiled.read_text(encoding="utf-8").replace("hello ", "HELLO ")
    compiled.write_text(text.replace(f"jinja2 {jinja2.__version__} ", "jinja2 0.1 ", 1), encoding="utf-8")
    assert _render() == "hello world"
    assert problems(_envs(), str) == []
    assert notes(_envs()) == [f"note: the precompiled templates were made by jinja2 0.1, this is jinja2 "
                              f"{jinja2.__version__}: they are compiled on each run until `python -m generator` "
                              "rewrites them"]
    assert refresh(_envs()) == [compiled] and notes(_envs()) == []


def test_a_precompiled_file_without_its_template_is_reported_and_removed(folders: tuple[Path, Path]) -> None:
    _, compiled = folders
    refresh(_envs())
    orphan = compiled.with_name("gone.pyj")
    shutil.copy(compiled, orphan)
    assert problems(_envs(), str) == [f"left over: {orphan} (its template is gone from t/; run `python -m generator`)"]
    assert refresh(_envs()) == [orphan] and not orphan.exists() and compiled.exists()


def test_check_reports_and_a_run_refreshes_the_real_set(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    copy = tmp_path / "precompiled"
    shutil.copytree(precompiled.PRECOMPILED, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(precompiled, "PRECOMPILED", copy)
    removed = copy / "python" / "{package}" / "__init__.py.pyj"
    removed.unlink()
    monkeypatch.chdir(REPO)
    out = tmp_path / "out"
    assert cli.main(["--out", str(out)]) == 0
    assert "1 precompiled template(s) rewritten" in capsys.readouterr().out and removed.is_file()
    removed.write_text(removed.read_text(encoding="utf-8").replace("sha256:", "sha256:0", 1), encoding="utf-8")
    assert cli.main(["--check", "--out", str(out)]) == 1
    assert f"stale: {removed}" in capsys.readouterr().out


def test_code_that_cannot_prove_its_source_is_not_used_and_is_written_again(folders: tuple[Path, Path]) -> None:
    _, compiled = folders
    refresh(_envs())
    lines = compiled.read_text(encoding="utf-8").replace("hello ", "HELLO ").splitlines(keepends=True)
    lines[1] = lines[1].replace("sha256:", "sha256:0")  # as bytecode Python kept of an older file would say
    compiled.write_text("".join(lines), encoding="utf-8")
    envs = _envs()
    assert envs["t"].get_template("sub/a.txt.j2").render(who="world") == "hello world"
    assert refresh(envs) == [compiled] and "HELLO" not in compiled.read_text(encoding="utf-8")


def test_the_shortened_code_renders_what_jinja_own_code_renders(monkeypatch: pytest.MonkeyPatch) -> None:
    spec = load_spec(REPO / "spec" / "drone.yaml")
    shortened = render_all(spec, environments())
    monkeypatch.setenv(precompiled.NO_PRECOMPILED, "1")
    monkeypatch.setattr(precompiled, "shorten", lambda code: code)
    assert render_all(spec, environments()) == shortened


@pytest.mark.parametrize(("source", "error", "message"), [
    ("{% if x %}{{ x | nosuch }}{% endif %}", jinja2.TemplateRuntimeError, "No filter named 'nosuch' found."),
    ("{% if x %}{{ x is nosuch }}{% endif %}", jinja2.TemplateRuntimeError, "No test named 'nosuch' found."),
    ("{% if x %}{{ who.name }}{% endif %}", jinja2.UndefinedError, "'who' is undefined"),
])
def test_the_shortened_code_fails_as_jinja_own_code_does(folders: tuple[Path, Path], source: str,
                                                          error: type[Exception], message: str) -> None:
    template, compiled = folders
    template.write_text(source, encoding="utf-8")
    env = jinja2.Environment(loader=PrecompiledLoader("t", "options"), undefined=jinja2.StrictUndefined)
    assert refresh({"t": env}) == [compiled] and "_defined(" in compiled.read_text(encoding="utf-8")
    assert env.get_template("sub/a.txt.j2").render(x=0) == ""  # a lookup or a variable never used: no error
    for used in (env, jinja2.Environment(undefined=jinja2.StrictUndefined)):  # precompiled, then Jinja's own
        loaded = used.get_template("sub/a.txt.j2") if used is env else used.from_string(source)
        with pytest.raises(error, match=f"^{message}$"):
            loaded.render(x=1)
