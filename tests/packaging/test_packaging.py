"""The codec installs alone from its wheel; the project's distribution claims no generic top-level name."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tomllib
import venv
import zipfile
from pathlib import Path

import drone_protocol as dp
import make_dist
import pytest

ROOT = Path(__file__).resolve().parents[2]
CODEC = ROOT / "generated" / "python"
BIN = Path(sys.executable).parent


def _run(*cmd: str | Path, cwd: Path, timeout: float = 300,
         env_extra: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")} | (env_extra or {})
    return subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)


def _wheel(source: Path, out: Path) -> Path:
    """`pip wheel` of a copy of `source` (so that the build cannot write into the repository)."""
    copy = out / "src"
    shutil.copytree(source, copy, ignore=shutil.ignore_patterns("__pycache__", ".venv", "build", "*.egg-info"))
    proc = _run(sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", out / "dist", copy, cwd=out)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    # quiet: no setuptools warnings such as "Package 'generator.templates...' would be ignored"
    assert "Warning" not in proc.stdout + proc.stderr, proc.stdout + proc.stderr
    (wheel,) = (out / "dist").glob("*.whl")
    return wheel


@pytest.fixture(scope="module")
def codec_wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _wheel(CODEC, tmp_path_factory.mktemp("codec"))


def _metadata(wheel: Path) -> str:
    with zipfile.ZipFile(wheel) as zf:
        name = next(n for n in zf.namelist() if n.endswith(".dist-info/METADATA"))
        return zf.read(name).decode("utf-8")


def test_the_codec_wheel_holds_the_package_alone(codec_wheel: Path) -> None:
    with zipfile.ZipFile(codec_wheel) as zf:
        names = zf.namelist()
    tops = {n.split("/")[0] for n in names}
    assert tops == {dp.PROTOCOL_NAME, f"{dp.PROTOCOL_NAME}-{dp.__version__}.dist-info"}, tops
    assert f"{dp.PROTOCOL_NAME}/py.typed" in names and f"{dp.PROTOCOL_NAME}/__init__.py" in names
    meta = _metadata(codec_wheel)
    assert re.search(rf"^Name: {dp.PROTOCOL_NAME.replace('_', '-')}$", meta, re.M)
    assert re.search(rf"^Version: {re.escape(dp.__version__)}$", meta, re.M)
    assert re.search(r"^Requires-Python: >=3\.9$", meta, re.M)
    assert "Requires-Dist" not in meta
    assert dp.SPEC_FINGERPRINT in meta  # the README is the long description
    assert re.search(r"^License-Expression: MIT$", meta, re.M) and "Project-URL" not in meta
    with zipfile.ZipFile(codec_wheel) as zf:
        licence = zf.read(f"{dp.PROTOCOL_NAME}-{dp.__version__}.dist-info/licenses/LICENSE")
    assert licence == (ROOT / "LICENSE").read_bytes()


def test_the_codec_wheel_installs_and_imports_in_a_fresh_venv_with_nothing_else(
    codec_wheel: Path, tmp_path: Path
) -> None:
    env_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    python = env_dir / "bin" / "python"
    proc = _run(python, "-m", "pip", "install", "-q", "--no-index", codec_wheel, cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    listed = _run(python, "-m", "pip", "list", "--format=json", cwd=tmp_path)
    installed = {p["name"].lower() for p in json.loads(listed.stdout)}
    assert installed - {"pip", "setuptools"} == {dp.PROTOCOL_NAME.replace("_", "-")}
    # the README's example, run as written, from a folder that is not the repository
    readme = (CODEC / "README.md").read_text(encoding="utf-8")
    (example,) = re.findall(r"```python\n(.*?)```", readme, re.S)
    check = (
        f"{example}\nimport {dp.PROTOCOL_NAME}, sys\n"
        f"assert {dp.PROTOCOL_NAME}.__file__.startswith(sys.prefix), {dp.PROTOCOL_NAME}.__file__\n"
        f"assert {dp.PROTOCOL_NAME}.decode(frame) == command\n"
        f"print({dp.PROTOCOL_NAME}.SPEC_FINGERPRINT)"
    )
    run = _run(python, "-I", "-c", check, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == dp.SPEC_FINGERPRINT


def test_the_project_wheel_installs_one_namespace_of_its_own(tmp_path: Path) -> None:
    wheel = _wheel(make_dist.copy_tools_source(tmp_path / "project"), tmp_path)
    with zipfile.ZipFile(wheel) as zf:
        names = zf.namelist()
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"drone_protocol_tools"}
    assert "drone_protocol_tools/generator/cli.py" in names and "drone_protocol_tools/pilot/app/cli.py" in names
    assert any(n.startswith("drone_protocol_tools/generator/templates/python/") for n in names)
    assert "drone_protocol_tools/generator/precompiled/arduino/{Library}/src/{Library}.h.pyj" in names
    # package data: the simulator's parameters and the virtual drone's sources (nothing read from the repository)
    assert {"drone_protocol_tools/pilot/sim/arducopter.yaml", "drone_protocol_tools/pilot/sim/drone.parm",
            "drone_protocol_tools/pilot/sim/firmware/host/virtual_drone.cpp"} <= set(names)
    meta = _metadata(wheel)
    assert re.search(r"^Requires-Python: >=3\.9$", meta, re.M)
    assert "Project-URL" not in meta and "Home-page" not in meta  # no placeholder: there is no public URL
    assert re.search(rf"^Requires-Dist: {dp.PROTOCOL_NAME.replace('_', '-')}$", _metadata(wheel), re.M)


def test_outside_the_repo_the_installed_names_are_the_namespaced_ones(tmp_path: Path) -> None:
    code = (
        "import importlib.util as u\n"
        "import drone_protocol_tools.generator.cli, drone_protocol_tools.pilot.app.cli\n"
        "print([n for n in ('generator', 'pilot') if u.find_spec(n) is not None])"
    )
    run = _run(sys.executable, "-c", code, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "[]"


def test_the_console_scripts_outside_the_repo(tmp_path: Path) -> None:
    gen = _run(BIN / "drone-protocol-gen", cwd=tmp_path)
    assert gen.returncode == 2 and not (tmp_path / "generated").exists()
    assert gen.stderr.count("\n") == 1 and "pass --spec FILE" in gen.stderr, gen.stderr
    helped = _run(BIN / "drone-protocol-gen", "--help", cwd=tmp_path)
    assert helped.returncode == 0 and "python -m generator" not in helped.stdout, helped.stdout
    assert helped.stdout.startswith("usage: drone-protocol-gen [-h]")
    assert "  drone-protocol-gen diff OLD [NEW]" in helped.stdout
    diff_help = _run(BIN / "drone-protocol-gen", "diff", "--help", cwd=tmp_path)
    assert diff_help.stdout.startswith("usage: drone-protocol-gen diff"), diff_help.stdout
    version = _run(BIN / "drone-protocol-gen", "--version", cwd=tmp_path)
    assert version.returncode == 0 and "no spec" in version.stdout
    with_spec = _run(BIN / "drone-protocol-gen", "--version", "--spec", ROOT / "spec" / "drone.yaml", cwd=tmp_path)
    assert with_spec.returncode == 0 and dp.SPEC_FINGERPRINT in with_spec.stdout
    pilot = _run(BIN / "pilot", "--version", cwd=tmp_path)
    assert pilot.returncode == 0 and dp.SPEC_FINGERPRINT in pilot.stdout, pilot.stdout + pilot.stderr


def test_the_crate_package_holds_its_readme_and_license_with_complete_metadata(tmp_path: Path) -> None:
    crate = ROOT / "generated" / "rust"
    listed = _run("cargo", "package", "--list", "--locked", "--offline", "--allow-dirty", cwd=crate,
                  env_extra={"CARGO_TARGET_DIR": str(tmp_path)})
    assert listed.returncode == 0, listed.stderr
    assert {"Cargo.toml", "README.md", "LICENSE"} <= set(listed.stdout.split())
    # cargo's "manifest has no documentation, homepage or repository" warning is gone
    assert "warning: manifest has no" not in listed.stderr, listed.stderr
    package = tomllib.loads((crate / "Cargo.toml").read_text(encoding="utf-8"))["package"]
    assert package["documentation"] == f"https://docs.rs/{package['name']}"
    assert "homepage" not in package and "repository" not in package  # none public: no placeholder


def test_the_crate_packages_with_no_warning_and_its_tests_run_from_the_package(tmp_path: Path) -> None:
    crate, target = tmp_path / "crate", tmp_path / "target"
    shutil.copytree(ROOT / "generated" / "rust", crate)  # cargo writes nothing into the repository
    env = {"CARGO_TARGET_DIR": str(target)}
    packaged = _run("cargo", "package", "--locked", "--offline", cwd=crate, env_extra=env)
    assert packaged.returncode == 0, packaged.stderr
    # e.g. "ignoring test `vectors` as `tests/vectors.rs` is not included in the published package"
    assert "warning" not in packaged.stderr.lower(), packaged.stderr
    (archive,) = (target / "package").glob("*.crate")
    with tarfile.open(archive) as tar:
        tar.extractall(tmp_path / "unpacked", filter="data")
    (unpacked,) = (tmp_path / "unpacked").iterdir()
    assert (unpacked / "tests" / "vectors.json").read_bytes() == (ROOT / "generated" / "vectors.json").read_bytes()
    # the packaged vectors test (the doctests run in make rust-test)
    tested = _run("cargo", "test", "--locked", "--offline", "--quiet", "--test", "vectors", cwd=unpacked, env_extra=env)
    assert tested.returncode == 0, tested.stdout + tested.stderr
    tests = (unpacked / "tests" / "vectors.rs").read_text(encoding="utf-8").count("#[test]")
    assert f"test result: ok. {tests} passed; 0 failed" in tested.stdout, tested.stdout
