# libFuzzer target for the generated C++ StreamParser, decode, encode, parse_reply (tests/fuzz/fuzz_stream_parser.cpp).
# Included by the top Makefile:  `make fuzz-smoke` (part of `make test`, ~35 s: the shipped spec, then in crc8
# mode)  and  `make fuzz` (5 minutes).
# Everything is built into build/fuzz/; the growing corpus stays in build/fuzz/corpus between runs, and a crash
# leaves its input in build/fuzz/artifacts/ (replay: build/fuzz/fuzz_stream_parser build/fuzz/artifacts/crash-...).
# With FUZZ_JOBS > 1 each worker logs to build/fuzz/fuzz-N.log.

FUZZ_DIR := build/fuzz
FUZZ_CXX ?= clang++
FUZZ_CXXFLAGS := -std=c++11 -g -O1 -Wall -Wextra -Werror -fsanitize=fuzzer,address,undefined \
                 -fno-sanitize-recover=all -fno-omit-frame-pointer
FUZZ_HEADER := generated/arduino/DroneProtocol/src/DroneProtocol.h
FUZZ_BIN := $(FUZZ_DIR)/fuzz_stream_parser
FUZZ_SEEDS := $(FUZZ_DIR)/seeds
FUZZ_DICT := $(FUZZ_DIR)/protocol.dict
FUZZ_SMOKE_SECONDS ?= 20
FUZZ_SECONDS ?= 300
FUZZ_JOBS ?= 1
# Runs inside $(FUZZ_DIR) (parallel jobs write their fuzz-N.log files there), so the paths are relative to it.
FUZZ_ARGS = -dict=protocol.dict -artifact_prefix=artifacts/ -max_len=256 -timeout=10 -rss_limit_mb=2048 \
            -print_final_stats=1
FUZZ_ENV := ASAN_OPTIONS=abort_on_error=1:detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

$(FUZZ_BIN): tests/fuzz/fuzz_stream_parser.cpp $(wildcard $(dir $(FUZZ_HEADER))*.h) tests/fuzz/fuzz.mk | $(APT_STAMP)
	@mkdir -p $(@D)
	$(FUZZ_CXX) $(FUZZ_CXXFLAGS) -I$(dir $(FUZZ_HEADER)) $< -o $@

$(FUZZ_DICT): generated/vectors.json tests/fuzz/make_fuzz_seeds.py | $(VENV_STAMP)
	@mkdir -p $(@D)
	$(PY) tests/fuzz/make_fuzz_seeds.py $< $(FUZZ_SEEDS) $@

# Brief run on every `make test`: the seeds (every conformance vector) first, then new inputs.
fuzz-smoke: $(FUZZ_BIN) $(FUZZ_DICT)
	@mkdir -p $(FUZZ_DIR)/corpus $(FUZZ_DIR)/artifacts
	cd $(FUZZ_DIR) && $(FUZZ_ENV) ./$(notdir $(FUZZ_BIN)) $(FUZZ_ARGS) -max_total_time=$(FUZZ_SMOKE_SECONDS) corpus seeds

# Longer run (FUZZ_SECONDS, FUZZ_JOBS parallel workers), e.g.  make fuzz FUZZ_SECONDS=3600 FUZZ_JOBS=4
fuzz: $(FUZZ_BIN) $(FUZZ_DICT)
	@mkdir -p $(FUZZ_DIR)/corpus $(FUZZ_DIR)/artifacts
	cd $(FUZZ_DIR) && $(FUZZ_ENV) ./$(notdir $(FUZZ_BIN)) $(FUZZ_ARGS) -max_total_time=$(FUZZ_SECONDS) \
	    $(if $(filter-out 1,$(FUZZ_JOBS)),-jobs=$(FUZZ_JOBS) -workers=$(FUZZ_JOBS)) corpus seeds

# The same target against the shipped spec in integrity mode crc8 (check digits, BadCheck's counter slot), a
# brief run on every `make test` too: build/fuzz/crc8 holds that spec, its generated library and its seeds.
FUZZ_CRC8 := $(FUZZ_DIR)/crc8
FUZZ_CRC8_SMOKE_SECONDS ?= 10

$(FUZZ_CRC8)/generated/vectors.json: spec/drone.yaml $(wildcard generator/*.py generator/templates/arduino/*/src/*) \
                                     | $(VENV_STAMP)
	@mkdir -p $(FUZZ_CRC8)
	@grep -q '^  integrity: none$$' $< || { echo "spec/drone.yaml: no '  integrity: none' line to switch" >&2; exit 1; }
	@sed 's/^  integrity: none$$/  integrity: crc8/' $< > $(FUZZ_CRC8)/drone.yaml
	@$(PY) -m generator --spec $(FUZZ_CRC8)/drone.yaml --out $(FUZZ_CRC8)/generated >/dev/null

$(FUZZ_CRC8)/fuzz_stream_parser: tests/fuzz/fuzz_stream_parser.cpp $(FUZZ_CRC8)/generated/vectors.json | $(APT_STAMP)
	$(FUZZ_CXX) $(FUZZ_CXXFLAGS) -I$(FUZZ_CRC8)/generated/arduino/DroneProtocol/src $< -o $@

$(FUZZ_CRC8)/protocol.dict: $(FUZZ_CRC8)/generated/vectors.json tests/fuzz/make_fuzz_seeds.py | $(VENV_STAMP)
	$(PY) tests/fuzz/make_fuzz_seeds.py $< $(FUZZ_CRC8)/seeds $@

fuzz-smoke: fuzz-smoke-crc8
.PHONY: fuzz-smoke-crc8
fuzz-smoke-crc8: $(FUZZ_CRC8)/fuzz_stream_parser $(FUZZ_CRC8)/protocol.dict
	@mkdir -p $(FUZZ_CRC8)/corpus $(FUZZ_CRC8)/artifacts
	cd $(FUZZ_CRC8) && $(FUZZ_ENV) ./fuzz_stream_parser $(FUZZ_ARGS) -max_total_time=$(FUZZ_CRC8_SMOKE_SECONDS) corpus seeds
