# Firmware benchmark (included from firmware/firmware.mk, which defines fw_board).
#
#   make bench-firmware   flash/RAM of the firmware and of a String-based baseline sketch, CPU cycles per frame
#                         from simavr for both, and the pulse jitter that parsing adds; writes
#                         bench/firmware/RESULTS.md

FW_BENCH_PIN := -DDRONE_BENCH_PIN=7
FW_BASELINE_SRC := bench/firmware/baseline/baseline.ino $(FW_DIR)/drone/pulse_out_avr.cpp \
                   $(FW_DIR)/drone/pulse_schedule.cpp

$(eval $(call fw_board,uno_bench,uno,$(FW_BENCH_PIN),$(FW_DRONE_SRC)))
$(eval $(call fw_board,uno_bench_nolead,uno,$(FW_BENCH_PIN) -DDRONE_PULSE_LEAD_US=0,$(FW_DRONE_SRC)))
$(eval $(call fw_board,baseline,uno,,$(FW_BASELINE_SRC)))
$(eval $(call fw_board,baseline_bench,uno,$(FW_BENCH_PIN),$(FW_BASELINE_SRC)))
$(eval $(call fw_board,uno_bench_parser,uno,-DDRONE_BENCH_PARSER_PIN=7,$(FW_DRONE_SRC)))
$(eval $(call fw_board,baseline_bench_parser,uno,-DDRONE_BENCH_PARSER_PIN=7,$(FW_BASELINE_SRC)))

FW_BENCH_BOARDS := uno uno_bench uno_bench_nolead uno_bench_parser baseline baseline_bench baseline_bench_parser
FW_BENCH_ELVES := $(foreach b,$(FW_BENCH_BOARDS),$(FW_BUILD)/$(b)/$(b).elf)

bench-firmware: $(VENV_STAMP) $(FW_BENCH_ELVES) $(FW_BUILD)/sim/drone_sim
	$(PY) bench/firmware/bench_firmware.py --build $(FW_BUILD)

# The generated parser alone: AVR cycles per byte, flash per command, spurious frames under corruption
# (bench/firmware/parser/parser_bench.py); writes bench/firmware/PARSER_RESULTS.md.
.PHONY: bench-parser
bench-parser: $(VENV_STAMP) $(FW_BUILD)/sim/drone_sim
	PYTHONPATH=. $(PY) bench/firmware/parser/parser_bench.py
bench-firmware: bench-parser
