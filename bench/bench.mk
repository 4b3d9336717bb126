# Benchmarks, included by the top-level Makefile (paths relative to the repository root).
#
#   make bench-protocol   Python codec vs f-string/slice floors, C++ StreamParser throughput and instructions per
#                         frame, parser flash/RAM on the ATmega328P; writes
#                         bench/protocol/RESULTS.md
#                         (and the Python codec's stream decoder in callgrind instructions against its floor:
#                         bench/protocol/PYTHON_INSTRUCTIONS.md)
#   make bench-generator  generator time for the shipped and a 676-command spec, rejecting hostile specs;
#                         writes bench/generator/RESULTS.md
#   make bench-vision     the detectors on real photographs (scikit-image's and scikit-learn's) under 10
#                         conditions (and a dark room at full gain, apart), empty and distractor views, tuning,
#                         held-out and validation photos, time vs
#                         the cvtColor+inRange floor; 400 views per condition, about 6 minutes on 2 cores;
#                         writes bench/vision/RESULTS.md (BENCH_VISION_FLAGS=--quick for a smoke run)
#   make bench-vision-dev the colour-ball detector on bench/vision's dev seed sets (tuning and validation photos, never
#                         the report's seeds), every candidate recorded in build/vision-dev/$(VISION_DEV_RECORD)
#                         (default: current), about 3 minutes on 2 cores; compare two records with
#                         bench/vision/vision_dev.py compare A B (how bench/vision/HISTORY.md measures a change)
#   make bench-vision-sources  the detectors on five packaged sources (scikit-image, scikit-learn, avr-libc,
#                         opencv-doc's photos and videos, matplotlib), split by source into tuning and held-out;
#                         installs the bench extra (pip) and Debian's opencv-doc; about 10 minutes on 2 cores; writes
#                         bench/vision/RESULTS-sources.md (BENCH_VISION_SOURCES_FLAGS="--views 20 --timing 20": smoke)
#   make bench-verifier   trains the colour-ball detector's learned verifier on the tuning sources only (its
#                         candidates on composites of the bench's ball: positives on the ball, negatives elsewhere),
#                         chooses its threshold on a second seed set, writes pilot/vision/verifier.yaml; about
#                         15 minutes on 2 cores (BENCH_VERIFIER_FLAGS="--views 40 --no-write": smoke)
#   make bench-tools      the standalone codec wheel's size and import time vs json; the live view's frame
#                         latency and the pilot loop's rate with and without a viewer; writes bench/tools/RESULTS.md
#   make bench-flight     the closed-loop campaign in the MuJoCo simulator: seeded flights per detector across
#                         every scenario, still air and gusts; success, non-target laser hits, crashes, the
#                         simulator's cost per frame; writes bench/flight/RESULTS.md (BENCH_FLIGHT_FLAGS=--seeds 2
#                         for a shorter one; "--detector hsv --first-seed 500 --seeds 4": seeds never tuned on,
#                         bench/flight/RESULTS-hsv-from500.md)
#   make bench-flight-strict  the strict campaign on held-out seeds (both detectors, gusts), then HSV with speed
#                         steps of 150 and 70 µs; bench/flight/RESULTS-held-out.md, RESULTS-step150.md, -step70.md
#   make bench-sidechan   the live view under 300 hostile clients (the loop's rate, gaps, memory), disk-full flights,
#                         the generator killed mid-run and malformed configs; writes bench/sidechan/RESULTS*.md
#   make bench            every part's benchmark: bench-protocol, bench-generator, bench-firmware
#                         (firmware/firmware.mk), bench-pilot (pilot/pilot.mk), bench-vision, bench-ide
#                         (bench/ide/bench.mk), bench-rust-c (tests/targets/targets.mk) and bench-tools
#
# BENCH_PROTOCOL_FLAGS=--quick for a smoke run (fewer repetitions; still writes RESULTS.md unless --no-write).

BENCH_PROTOCOL_BUILD ?= build/bench/protocol
BENCH_PROTOCOL_FLAGS ?=

BENCH_VISION_FLAGS ?=
BENCH_VISION_SOURCES_FLAGS ?=
BENCH_VERIFIER_FLAGS ?=
BENCH_VISION_APT := opencv-doc avr-libc  # the packaged imagery of bench-vision-sources (bench/vision/packaged.py)
VISION_DEV_RECORD ?= current
BENCH_FLIGHT_FLAGS ?=

.PHONY: bench bench-protocol bench-generator bench-firmware bench-pilot bench-vision bench-vision-sources bench-vision-dev \
        bench-verifier \
        bench-ide bench-tools bench-flight bench-flight-strict bench-sidechan

# Run benchmarks one at a time (not with make -j): they time each other otherwise.
bench: bench-protocol bench-generator bench-firmware bench-pilot bench-vision bench-ide bench-rust-c bench-tools \
       bench-flight

bench-flight: deps firmware-host
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.flight.run $(BENCH_FLIGHT_FLAGS)

# The strict campaign on held-out seeds (11 seeds x 14 scenarios = 154 flights per detector, gusts too), then the
# HSV flights again with speed steps of 150 and 70 µs: bench/flight/RESULTS-held-out.md, RESULTS-step150.md, -step70.md
BENCH_FLIGHT_STRICT_FLAGS ?= --seeds 11 --gust-seeds 4 --processes 2
bench-flight-strict: deps firmware-host
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.flight.run --held-out $(BENCH_FLIGHT_STRICT_FLAGS)
	for step in 150 70; do PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.flight.run --held-out \
	  --step-us $$step $(BENCH_FLIGHT_STRICT_FLAGS) || exit 1; done

bench-vision: deps
	PYTHONPATH=.:bench/vision $(PY) bench/vision/run.py $(BENCH_VISION_FLAGS)

bench-verifier: deps
	$(PY) -m pip install -q -e '.[bench]'
	PYTHONPATH=.:bench/vision $(PY) bench/vision/train_verifier.py $(BENCH_VERIFIER_FLAGS)

bench-vision-sources: deps
	@missing=$$(for p in $(BENCH_VISION_APT); do dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null \
	    | grep -q "install ok installed" || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then echo "Installing Debian packages:" $$missing; apt-get update -qq && \
	    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing >/dev/null || exit 1; \
	  else echo "Missing Debian packages. Run:  sudo apt-get install -y $$missing"; exit 1; fi; \
	fi
	$(PY) -m pip install -q -e '.[bench]'
	PYTHONPATH=.:bench/vision $(PY) bench/vision/sources_run.py $(BENCH_VISION_SOURCES_FLAGS)

bench-vision-dev: deps
	PYTHONPATH=.:bench/vision $(PY) bench/vision/vision_dev.py record $(VISION_DEV_RECORD)

bench-protocol: deps
	$(PY) -m bench.protocol.run --build $(BENCH_PROTOCOL_BUILD) $(BENCH_PROTOCOL_FLAGS)
	$(PY) -m bench.protocol.python_instructions

bench-generator: deps
	$(PY) -m bench.generator.run

BENCH_TOOLS_FLAGS ?=
bench-tools: deps firmware-host
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.tools.run $(BENCH_TOOLS_FLAGS)

bench-sidechan: deps firmware-host
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.sidechan.liveview_load $(BENCH_SIDECHAN_FLAGS)
	$(PY) -m bench.sidechan.liveview_load --synthetic-pairs 6
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.sidechan.liveview_cost
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.sidechan.liveview_cost --realtime 10
	PILOT_VIRTUAL_DRONE=$(FW_BUILD)/host/virtual_drone $(PY) -m bench.sidechan.disk_full
	$(PY) -m bench.sidechan.generator_kills
	$(PY) -m bench.sidechan.bad_configs

# Recipes come from firmware/firmware.mk and pilot/pilot.mk; a part that has none yet benchmarks nothing.
bench-firmware bench-pilot:
