# The two commands of the README:  `make demo`  and  `make test`.
# Both install what they need: Debian packages (apt-get, when run as root; otherwise they name what to
# install) and a Python virtual environment in .venv.

SHELL := /bin/bash
PYTHON_SYSTEM ?= python3
VENV := .venv
PY := $(VENV)/bin/python
VENV_STAMP := $(VENV)/.installed
APT_STAMP := build/.apt-packages

# Debian 12 packages: the AVR toolchain and Arduino core, arduino-builder (the IDE's builder) and avrdude,
# simavr, host compilers, clang + libFuzzer, valgrind, Chromium and its WebDriver (the browser tests),
# Mesa's off-screen OpenGL (MuJoCo renders the simulator's camera headless).
APT_PACKAGES := make gcc g++ python3 python3-venv python3-pip gcc-avr binutils-avr avr-libc arduino-core-avr \
                arduino-builder avrdude \
                simavr libsimavr-dev libelf-dev pkg-config clang libclang-rt-14-dev valgrind \
                chromium chromium-driver libosmesa6 libgl1-mesa-dri libegl1

.PHONY: all demo test deps generate check-generated lint typecheck pytest fuzz fuzz-smoke bench clean dist pythons

all: generate

deps: $(APT_STAMP) $(VENV_STAMP)

$(APT_STAMP): Makefile  # a package added here is installed on the next run
	@missing=$$(for p in $(APT_PACKAGES); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null \
	    | grep -q "install ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "Installing Debian packages:" $$missing; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; \
	  else \
	    echo "Missing Debian packages. Run:  sudo apt-get install -y $$missing"; exit 1; \
	  fi; \
	fi
	@mkdir -p $(dir $@) && touch $@

# The codec (generated/python, its own distribution) first, then the project, which depends on it; both editable.
$(VENV_STAMP): pyproject.toml setup.py generated/python/pyproject.toml
	@test -x $(PY) || $(PYTHON_SYSTEM) -m venv $(VENV)
	@echo "Installing the Python environment in $(VENV) (the codec, the project and its dev tools)"
	@mkdir -p build
	@# pip's and setuptools' chatter goes to a log, shown only when the install fails; --no-compile: byte-compiling
	@# every module of scipy, scikit-learn and the rest was most of the install's time (Python compiles what it imports)
	@{ $(PY) -m pip install -q --upgrade pip && $(PY) -m pip install -q --no-compile -e generated/python -e '.[dev]'; } \
	  >build/pip-install.log 2>&1 || { cat build/pip-install.log; echo "pip install failed (log: build/pip-install.log)"; exit 1; }
	@touch $@

generate: $(VENV_STAMP)
	$(PY) -m generator

check-generated: $(VENV_STAMP)
	$(PY) -m generator --check

lint: $(VENV_STAMP)
	$(VENV)/bin/ruff check --output-format concise .

typecheck: $(VENV_STAMP)
	$(VENV)/bin/mypy --strict generator generated/python/drone_protocol pilot tests bench firmware/ide

# tests/packaging/test_install.py installs the wheels on the oldest and the newest Python supported
INSTALL_TEST_PYTHONS := 3.9 3.13

pythons:
	@for v in $(INSTALL_TEST_PYTHONS); do command -v python$$v >/dev/null || ls -d $${PYENV_ROOT:-$$HOME/.pyenv}/versions/$$v.* \
	  >/dev/null 2>&1 || { command -v pyenv >/dev/null && pyenv install -s $$v; } || \
	  { echo "Python $$v is missing: install pyenv (https://github.com/pyenv/pyenv) and run  pyenv install $$v"; exit 1; }; done

# without make's own variables: under `make -j2` (make test) they name a jobserver the tests' own make calls cannot
# reach, and those print a warning the tests read as output
pytest: deps pythons
	env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL $(PY) -m pytest -q -n 2 --dist loadgroup --no-loadscope-reorder tests

# After pytest, the native targets' own tests (fuzz-smoke here; targets.mk and typescript.mk add theirs to TEST_TAIL)
# run two at a time: each is one process for most of its time, and they build into folders of their own.
# The type check (one process, about 50 s cold) runs beside pytest: alone before it, it left a core idle.
TEST_TAIL := fuzz-smoke
test: deps check-generated lint
	@$(MAKE) --no-print-directory -j2 --output-sync=target typecheck pytest
	@$(MAKE) --no-print-directory -j2 --output-sync=target $(TEST_TAIL)

demo: deps generate
	$(PY) -m generator.demo
	$(MAKE) --no-print-directory demo-flight

-include firmware/firmware.mk
-include pilot/pilot.mk
-include tests/fuzz/fuzz.mk
-include bench/bench.mk
-include tests/targets/targets.mk
-include tests/targets/typescript.mk

# Every package into dist/: the codec's and the tools' wheels, the npm tarball and the crate.
DIST := dist
dist: $(VENV_STAMP) $(TS_STAMP) cargo-available
	@rm -rf $(DIST) && mkdir -p $(DIST)
	$(PY) tests/packaging/make_dist.py $(DIST)
	cp $(TS_BUILD)/*.tgz $(DIST)/
	@rm -f build/rust/target/package/*.crate
	$(CARGO_RUN) package $(CARGO_FLAGS) --allow-dirty --no-verify --quiet
	cp build/rust/target/package/*.crate $(DIST)/
	@ls -l $(DIST)

clean:
	rm -rf build firmware/build dist
