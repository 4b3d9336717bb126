# The Arduino IDE path and flashing, included from firmware/firmware.mk (paths relative to the repository root).
#
#   make upload PORT=/dev/ttyACM0 BOARD=uno|mega|uno_ppm   build that board's .hex and flash it with avrdude
#                                                           (DRY_RUN=1 prints the avrdude command only)
#   make arduino-library        build/arduino/DroneProtocol-<version>.zip, with the DroneFirmware example, for
#                               the IDE's Sketch > Include Library > Add .ZIP Library
#   make arduino-install SKETCHBOOK=~/Arduino   the same library installed into a sketchbook's libraries/

AVRDUDE ?= avrdude
BOARD ?= uno
# Each bootloader's programmer protocol and baud: optiboot on the Uno, stk500v2 ("wiring") on the Mega 2560.
# -D: no chip erase (the bootloaders erase page by page; the Mega's refuses a chip erase).
UPLOAD_ARGS_uno := -p m328p -c arduino -b 115200 -D
UPLOAD_ARGS_uno_ppm := $(UPLOAD_ARGS_uno)
UPLOAD_ARGS_mega := -p m2560 -c wiring -b 115200 -D
UPLOAD_HEX = $(FW_BUILD)/$(BOARD)/$(BOARD).hex

# Checked before anything is built, each refusal one line (make prints it and exits 2).
ifneq ($(filter upload,$(MAKECMDGOALS)),)
ifeq ($(UPLOAD_ARGS_$(BOARD)),)
$(error BOARD=$(BOARD) is not a board we build: use BOARD=uno, BOARD=mega or BOARD=uno_ppm)
endif
ifeq ($(strip $(PORT)),)
$(error PORT is not set: make upload PORT=/dev/ttyACM0 BOARD=$(BOARD) (ls /dev/ttyACM* /dev/ttyUSB* lists the boards plugged in))
endif
ifeq ($(wildcard $(PORT)),)
$(error PORT=$(PORT) does not exist: is the board plugged in? (ls /dev/ttyACM* /dev/ttyUSB* lists the ones that are))
endif
endif

.PHONY: upload arduino-library arduino-install

upload: $(APT_STAMP) $(UPLOAD_HEX)
	@echo "Flashing $(UPLOAD_HEX) (BOARD=$(BOARD)) to $(PORT):"
	@echo "  $(AVRDUDE) $(UPLOAD_ARGS_$(BOARD)) -P $(PORT) -U flash:w:$(UPLOAD_HEX):i"
	@$(if $(DRY_RUN),echo "  (DRY_RUN: not run)",$(AVRDUDE) $(UPLOAD_ARGS_$(BOARD)) -P $(PORT) -U flash:w:$(UPLOAD_HEX):i)

arduino-library: $(VENV_STAMP)
	@$(PY) firmware/ide/sketchbook.py zip build/arduino

arduino-install: $(VENV_STAMP)
	@test -n "$(SKETCHBOOK)" || { echo "SKETCHBOOK is not set: make arduino-install SKETCHBOOK=~/Arduino" >&2; exit 2; }
	@$(PY) firmware/ide/sketchbook.py install "$(SKETCHBOOK)"

-include bench/ide/bench.mk
