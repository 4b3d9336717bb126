# The Rust crate (generated/rust) and the C99 codec (generated/c): native tests, linters, bare-metal builds and a
# libFuzzer smoke run. Included by the top Makefile; `make targets-test` is part of `make test`.
#
#   make rust-test       cargo fmt --check (the generated code is rustfmt's output), cargo test (vectors.json, replies,
#                        seeded random streams, README doctest), clippy -D warnings,
#                        a bare-metal build (thumbv7em-none-eabihf through rustup; a host no_std build if refused),
#                        cargo package
#   make c-test          the codec with gcc and clang (-std=c99 -pedantic -Werror), for the ATmega328P with avr-gcc,
#                        and the C tests over vectors.json under ASan/UBSan
#   make c-fuzz-smoke    libFuzzer on the C codec for C_FUZZ_SECONDS (c-fuzz: C_FUZZ_LONG_SECONDS)
# Cargo builds into build/rust/target, offline, against the committed Cargo.lock (the crate has no dependencies).

TARGETS_BUILD := build/targets
# no MAKEFLAGS: a `make -j` above would hand cargo a jobserver whose descriptors this recipe line does not get
CARGO_RUN := cd generated/rust && MAKEFLAGS= MFLAGS= CARGO_TARGET_DIR=$(CURDIR)/build/rust/target cargo
CARGO_FLAGS := --locked --offline
RUST_BARE_METAL ?= thumbv7em-none-eabihf
C_DIR := generated/c
C_SOURCES := $(wildcard $(C_DIR)/*.c)
C_STRICT := -std=c99 -Wall -Wextra -Werror -pedantic
C_FUZZ_SECONDS ?= 15
C_FUZZ_LONG_SECONDS ?= 300

.PHONY: targets-test rust-test c-test c-fuzz-smoke c-fuzz cargo-available

TEST_TAIL += targets-test

targets-test: rust-test c-test c-fuzz-smoke

cargo-available:
	@command -v cargo >/dev/null || { echo "cargo is missing: install Rust with rustup (https://rustup.rs)"; exit 1; }

rust-test: cargo-available
	@cargo fmt --version >/dev/null 2>&1 || rustup component add rustfmt
	$(CARGO_RUN) fmt --check
	$(CARGO_RUN) test $(CARGO_FLAGS) --quiet
	$(CARGO_RUN) clippy $(CARGO_FLAGS) --all-targets --quiet -- -D warnings
	@if rustup target list --installed 2>/dev/null | grep -qx $(RUST_BARE_METAL) || rustup target add $(RUST_BARE_METAL); then \
	  echo "bare-metal build for $(RUST_BARE_METAL):"; \
	  $(CARGO_RUN) build $(CARGO_FLAGS) --release --quiet --target $(RUST_BARE_METAL); \
	else \
	  echo "NOTE: rustup could not add $(RUST_BARE_METAL); falling back to a host build of the #![no_std] crate"; \
	  $(CARGO_RUN) build $(CARGO_FLAGS) --release --quiet; \
	fi
	$(CARGO_RUN) package $(CARGO_FLAGS) --allow-dirty --no-verify --quiet
	@echo "rust: rustfmt, tests, clippy, bare-metal build and package OK"

$(TARGETS_BUILD)/test_c_codec: tests/targets/c/test_c_codec.c tests/targets/c/reference.h $(C_SOURCES) $(C_DIR)/*.h
	@mkdir -p $(@D)
	gcc $(C_STRICT) -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all -I$(C_DIR) $< $(C_SOURCES) -o $@

c-test: $(TARGETS_BUILD)/test_c_codec | $(APT_STAMP)
	@mkdir -p $(TARGETS_BUILD)
	gcc $(C_STRICT) -O2 -c $(C_SOURCES) -o $(TARGETS_BUILD)/codec-gcc.o
	clang $(C_STRICT) -Wconversion -Wshadow -O2 -c $(C_SOURCES) -o $(TARGETS_BUILD)/codec-clang.o
	avr-gcc $(C_STRICT) -Os -mmcu=atmega328p -c $(C_SOURCES) -o $(TARGETS_BUILD)/codec-avr.o
	@! grep -nE '#include <(stdio|stdlib)\.h>|malloc|free\(' $(C_DIR)/*.[ch] || { echo "the C codec must not use stdio or the heap"; exit 1; }
	$(TARGETS_BUILD)/test_c_codec generated/vectors.json

$(TARGETS_BUILD)/fuzz_c_codec: tests/targets/c/fuzz_c_codec.c tests/targets/c/reference.h $(C_SOURCES) $(C_DIR)/*.h | $(APT_STAMP)
	@mkdir -p $(@D)
	clang -std=c99 -g -O1 -Wall -Wextra -Werror -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	    -fno-omit-frame-pointer -I$(C_DIR) $< $(C_SOURCES) -o $@

$(TARGETS_BUILD)/c.dict: generated/vectors.json tests/fuzz/make_fuzz_seeds.py | $(VENV_STAMP)
	@mkdir -p $(@D)
	$(PY) tests/fuzz/make_fuzz_seeds.py $< $(TARGETS_BUILD)/c-seeds $@

C_FUZZ_RUN = cd $(TARGETS_BUILD) && mkdir -p c-corpus c-artifacts && \
    ASAN_OPTIONS=abort_on_error=1:detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ./fuzz_c_codec -dict=c.dict -artifact_prefix=c-artifacts/ -max_len=256 -timeout=10 -print_final_stats=1

c-fuzz-smoke: $(TARGETS_BUILD)/fuzz_c_codec $(TARGETS_BUILD)/c.dict
	$(C_FUZZ_RUN) -max_total_time=$(C_FUZZ_SECONDS) c-corpus c-seeds 2>&1 | { grep -E '^(Done|stat::number_of_executed_units)|ERROR|invariant|SUMMARY|artifact' || true; }; exit $${PIPESTATUS[0]}

c-fuzz: $(TARGETS_BUILD)/fuzz_c_codec $(TARGETS_BUILD)/c.dict
	$(C_FUZZ_RUN) -max_total_time=$(C_FUZZ_LONG_SECONDS) c-corpus c-seeds

# Benchmarks (not part of make test): writes bench/rust_c/RESULTS.md.
.PHONY: bench-rust-c
bench: bench-rust-c
bench-rust-c: deps cargo-available
	$(PY) bench/rust_c/run.py
	$(PY) bench/rust_c/instructions.py
