# The pilot's targets, included by the top-level Makefile (paths relative to the repository root).
#
#   make demo-flight    fly the simulated room against the virtual drone (real firmware logic over a pty),
#                       find the target, fire the laser at it, land; prints where the recording and the
#                       path picture are (build/demo-flight/)
#   make pilot-test     the pilot's tests only (tests/pilot)
#   make bench-pilot    detection time vs the cvtColor+inRange floor, frame-to-last-byte latency, simulated
#                       flights per minute; writes bench/pilot/RESULTS.md
#
# DEMO_FLIGHT_ARGS picks another flight, e.g. DEMO_FLIGHT_ARGS="--scenario hidden --seed 4".
# BENCH_PILOT_FLAGS=--quick for a smoke run.

DEMO_FLIGHT_DIR ?= build/demo-flight
# The demo flies the randomised world (the default of `pilot --sim`): the pilot learns the airframe's trim drift from
# the target (pilot/control/trim.py); this flight succeeds by the strict score (bench/flight/HISTORY.md).
DEMO_FLIGHT_ARGS ?= --scenario behind --seed 3
BENCH_PILOT_FLAGS ?=
PILOT_VD = $(FW_BUILD)/host/virtual_drone

.PHONY: demo-flight pilot-test bench-pilot

demo-flight: deps firmware-host
	@rm -rf $(DEMO_FLIGHT_DIR)
	$(PY) -m pilot --virtual-drone $(PILOT_VD) --record $(DEMO_FLIGHT_DIR) $(DEMO_FLIGHT_ARGS)

pilot-test: deps
	$(PY) -m pytest -q tests/pilot

bench-pilot: deps firmware-host
	PILOT_VIRTUAL_DRONE=$(PILOT_VD) $(PY) -m bench.pilot.run $(BENCH_PILOT_FLAGS)
