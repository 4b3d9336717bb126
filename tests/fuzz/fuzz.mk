# libFuzzer target for the generated C++ StreamParser / decode / encode (tests/fuzz/fuzz_stream_parser.cpp).
# Included by the top Makefile:  `make fuzz-smoke` (part of `make test`, ~20 s)  and  `make fuzz` (5 minutes).
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
