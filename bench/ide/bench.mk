# Arduino IDE benchmark (included from firmware/ide/ide.mk, which comes after fw_board is defined).
#
#   make bench-ide   flash/RAM of every library example and of the firmware built by arduino-builder (the
#                    Arduino IDE's builder) against the same sketches built by our makefile; writes
#                    bench/ide/RESULTS.md

IDE_EXAMPLES_DIR := $(DRONE_PROTOCOL_DIR)/examples
IDE_EXAMPLES := $(notdir $(wildcard $(IDE_EXAMPLES_DIR)/*))
# Each example through our own makefile rule (avr-gcc, -Wall -Wextra -Werror), for both boards.
$(foreach e,$(IDE_EXAMPLES),$(eval $(call fw_board,ex_$(e)_uno,uno,,$(IDE_EXAMPLES_DIR)/$(e)/$(e).ino)))
$(foreach e,$(IDE_EXAMPLES),$(eval $(call fw_board,ex_$(e)_mega,mega,,$(IDE_EXAMPLES_DIR)/$(e)/$(e).ino)))
IDE_BENCH_ELVES := $(FW_ELVES) $(foreach e,$(IDE_EXAMPLES),$(foreach b,uno mega,$(FW_BUILD)/ex_$(e)_$(b)/ex_$(e)_$(b).elf))

.PHONY: bench-ide
bench-ide: $(APT_STAMP) $(VENV_STAMP) $(IDE_BENCH_ELVES)
	PYTHONPATH=$(FW_DIR)/ide $(PY) bench/ide/run.py --build $(FW_BUILD)
