# The TypeScript target, included by the top-level Makefile (paths relative to the repository root).
#
#   make typescript          build and pack the generated package: build/typescript/drone-protocol-*.tgz, with
#                            dist/ (JS + .d.ts) and dist/console.html (the bench console, one self-contained page)
#   make typescript-test     its tests with Node's test runner: vectors, stream parser against the Python one,
#                            seeded random bytes, the packed tarball installed into a temporary project, the usage
#                            examples of the README and the docs, the bench console in headless Chromium against
#                            the virtual drone (part of `make test`)
#   make typescript-console  the virtual drone behind a WebSocket bridge, for the console in a browser by hand
#   make bench-typescript    encode/decode per frame and stream parser per byte against hand-written floors, in
#                            time and in instructions (callgrind); writes bench/typescript/RESULTS.md
#
# The test tools (typescript, playwright-core, ws) are pinned in tests/targets/typescript/package-lock.json and
# installed into tests/targets/typescript/node_modules: nothing global. Chromium comes from Debian.

TS_TOOLS_DIR := tests/targets/typescript
TS_TOOLS := $(TS_TOOLS_DIR)/node_modules/.installed
TS_BIN := $(abspath $(TS_TOOLS_DIR)/node_modules/.bin)
TS_BUILD := build/typescript
TS_PACKAGE := $(TS_BUILD)/package
TS_STAMP := $(TS_BUILD)/.packed
TS_SOURCES = $(shell find generated/typescript -type f)
TS_CHROMIUM := build/.apt-chromium
TS_ENV = DRONE_PROTOCOL_TS_BUILD=$(abspath $(TS_BUILD)) DRONE_PROTOCOL_PYTHON=$(abspath $(PY)) \
         DRONE_PROTOCOL_VIRTUAL_DRONE=$(abspath $(FW_HOST_DIR)/virtual_drone)

.PHONY: typescript typescript-test typescript-console bench-typescript

TEST_TAIL += typescript-test

# Node and npm: Debian's when missing (a machine with NodeSource's node already has both).
$(TS_TOOLS): $(TS_TOOLS_DIR)/package.json $(TS_TOOLS_DIR)/package-lock.json
	@command -v node >/dev/null && command -v npm >/dev/null || { \
	  if [ "$$(id -u)" = 0 ]; then apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq nodejs npm >/dev/null; \
	  else echo "Node.js >= 18 and npm are missing. Run:  sudo apt-get install -y nodejs npm"; exit 1; fi; }
	@node -e 'process.exit(Number(process.versions.node.split(".")[0]) >= 18 ? 0 : 1)' || { echo "Node.js >= 18 needed, found $$(node --version)"; exit 1; }
	cd $(TS_TOOLS_DIR) && npm ci --no-audit --no-fund --loglevel=error
	@touch $@

$(TS_CHROMIUM):
	@dpkg-query -W -f='$${Status}\n' chromium chromium-driver 2>/dev/null | grep -c "install ok installed" | grep -q 2 || { \
	  if [ "$$(id -u)" = 0 ]; then apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver >/dev/null; \
	  else echo "Chromium is missing. Run:  sudo apt-get install -y chromium chromium-driver"; exit 1; fi; }
	@mkdir -p $(dir $@) && touch $@

# A copy of generated/typescript packed the way a user does (`npm pack` runs the package's build: tsc and the
# console bundler), with this repository's pinned tsc on PATH instead of a node_modules inside generated/.
$(TS_STAMP): $(TS_TOOLS) $(TS_SOURCES)
	@rm -rf $(TS_PACKAGE) $(TS_BUILD)/*.tgz && mkdir -p $(TS_PACKAGE)
	@cp -R generated/typescript/. $(TS_PACKAGE)/
	cd $(TS_PACKAGE) && PATH="$(TS_BIN):$$PATH" npm pack --pack-destination .. --loglevel=error >/dev/null
	@ls $(TS_BUILD)/*.tgz
	@touch $@

typescript: $(TS_STAMP)

typescript-test: $(TS_STAMP) $(TS_CHROMIUM) $(VENV_STAMP) $(FW_HOST_DIR)/virtual_drone
	cd $(TS_TOOLS_DIR) && $(TS_ENV) node --test --test-reporter=spec tests/*.test.mjs

typescript-console: $(TS_STAMP) $(FW_HOST_DIR)/virtual_drone
	$(TS_ENV) node $(TS_TOOLS_DIR)/ws_bridge.mjs

bench-typescript: $(TS_STAMP) $(VENV_STAMP)
	$(TS_ENV) node bench/typescript/bench.mjs
	$(PY) bench/typescript/instructions.py
bench: bench-typescript
