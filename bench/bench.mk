# Benchmarks, included by the top-level Makefile (paths relative to the repository root).
#
#   make bench-protocol   Python codec vs f-string/slice floors, C++ StreamParser throughput and instructions per
#                         frame, parser flash/RAM on the ATmega328P, generator run time; writes
#                         bench/protocol/RESULTS.md
#   make bench-generator  generator time for the shipped and a 676-command spec, rejecting hostile specs;
#                         writes bench/generator/RESULTS.md
#   make bench            every part's benchmark: bench-protocol, bench-generator, bench-firmware
#                         (firmware/firmware.mk) and bench-pilot (pilot/pilot.mk)
#
# BENCH_PROTOCOL_FLAGS=--quick for a smoke run (fewer repetitions; still writes RESULTS.md unless --no-write).

BENCH_PROTOCOL_BUILD ?= build/bench/protocol
BENCH_PROTOCOL_FLAGS ?=

.PHONY: bench bench-protocol bench-generator bench-firmware bench-pilot

# Run benchmarks one at a time (not with make -j): they time each other otherwise.
bench: bench-protocol bench-generator bench-firmware bench-pilot

bench-protocol: deps
	$(PY) bench/protocol/run.py --build $(BENCH_PROTOCOL_BUILD) $(BENCH_PROTOCOL_FLAGS)

bench-generator: deps
	$(PY) bench/generator/run.py

# Recipes come from firmware/firmware.mk and pilot/pilot.mk; a part that has none yet benchmarks nothing.
bench-firmware bench-pilot:
