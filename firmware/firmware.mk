# Firmware builds, included by the top-level Makefile (paths are relative to
# the repository root, which is where make runs).
#
#   make firmware          Uno + Mega 2560 .elf/.hex (and the Uno PPM-sum build), flash/RAM printed
#   make firmware-host     virtual_drone and the host test programs
#   make firmware-sim      the simavr harness
#   make bench-firmware    flash/RAM, cycles per frame and pulse jitter vs a String-based baseline
#
# Overridable: DRONE_PROTOCOL_DIR (the generated Arduino library to build
# against) and FW_BUILD (where everything goes), so a test can rebuild the
# firmware from a regenerated spec in a temporary directory.

FW_DIR := firmware
FW_BUILD ?= $(FW_DIR)/build
DRONE_PROTOCOL_DIR ?= generated/arduino/DroneProtocol
ARDUINO_AVR ?= /usr/share/arduino/hardware/arduino/avr
ARDUINO_CORE := $(ARDUINO_AVR)/cores/arduino

AVR_CC ?= avr-gcc
AVR_CXX ?= avr-g++
AVR_OBJCOPY ?= avr-objcopy
AVR_SIZE ?= avr-size
HOST_CXX ?= g++
HOST_CC ?= gcc

FW_SKETCH_SRC := $(FW_DIR)/drone/drone_app.cpp $(FW_DIR)/drone/drone_logic.cpp $(FW_DIR)/drone/drone_handlers.cpp \
                 $(FW_DIR)/drone/pulse_schedule.cpp $(FW_DIR)/drone/pulse_out_avr.cpp \
                 $(FW_DIR)/drone/serial_avr.cpp
FW_HEADERS := $(wildcard $(FW_DIR)/drone/*.h)
FW_PROTO_SRC = $(wildcard $(DRONE_PROTOCOL_DIR)/src/*.cpp)
FW_PROTO_HDR = $(wildcard $(DRONE_PROTOCOL_DIR)/src/*.h)

FW_WARN := -Wall -Wextra -Werror
FW_AVR_COMMON := -Os -g -ffunction-sections -fdata-sections -flto -DF_CPU=16000000L -DARDUINO=10819 \
                 -DARDUINO_ARCH_AVR
FW_AVR_CFLAGS := -std=gnu11 -fno-fat-lto-objects
FW_AVR_CXXFLAGS := -std=gnu++11 -fno-exceptions -fno-threadsafe-statics -DDECIMAL_DIG=__DECIMAL_DIG__

FW_CORE_C := $(wildcard $(ARDUINO_CORE)/*.c)
FW_CORE_CXX := $(wildcard $(ARDUINO_CORE)/*.cpp)
FW_CORE_S := $(wildcard $(ARDUINO_CORE)/*.S)

# The Arduino core, built once per board type and shared by every build for
# it (the sketch's own defines do not reach the core). FW_CORE_BUILD may point
# elsewhere than FW_BUILD so that a temporary build reuses the cores.
FW_CORE_BUILD ?= $(FW_BUILD)

# $(call fw_core,KEY,MCU,VARIANT,BOARD_DEFINE) -> $(FW_CORE_BUILD)/core_KEY/core.a
define fw_core
FW_CORE_$(1)_DIR := $$(FW_CORE_BUILD)/core_$(1)
FW_CORE_$(1)_FLAGS := -mmcu=$(2) $$(FW_AVR_COMMON) -DARDUINO_$(4) -I$$(ARDUINO_CORE) -I$$(ARDUINO_AVR)/variants/$(3)
FW_CORE_$(1)_OBJ := $$(patsubst $$(ARDUINO_CORE)/%,$$(FW_CORE_$(1)_DIR)/%.o,$$(FW_CORE_C) $$(FW_CORE_CXX) $$(FW_CORE_S))

$$(FW_CORE_$(1)_DIR)/%.c.o: $$(ARDUINO_CORE)/%.c
	@mkdir -p $$(@D)
	@$$(AVR_CC) -c -w $$(FW_CORE_$(1)_FLAGS) $$(FW_AVR_CFLAGS) $$< -o $$@
$$(FW_CORE_$(1)_DIR)/%.cpp.o: $$(ARDUINO_CORE)/%.cpp
	@mkdir -p $$(@D)
	@$$(AVR_CXX) -c -w $$(FW_CORE_$(1)_FLAGS) $$(FW_AVR_CXXFLAGS) $$< -o $$@
$$(FW_CORE_$(1)_DIR)/%.S.o: $$(ARDUINO_CORE)/%.S
	@mkdir -p $$(@D)
	@$$(AVR_CC) -c -x assembler-with-cpp $$(FW_CORE_$(1)_FLAGS) $$< -o $$@
$$(FW_CORE_$(1)_DIR)/core.a: $$(FW_CORE_$(1)_OBJ)
	@rm -f $$@
	@echo "  AR    $$@ (Arduino core)"
	@avr-gcc-ar rcs $$@ $$^
endef

$(eval $(call fw_core,uno,atmega328p,standard,AVR_UNO))
$(eval $(call fw_core,mega,atmega2560,mega,AVR_MEGA2560))
# Linker relaxation (call -> rcall where it reaches) on the Mega 2560, as the Arduino IDE links it.
FW_CORE_mega_LDFLAGS := -Wl,--relax

# $(call fw_board,NAME,CORE_KEY,EXTRA_DEFINES,SKETCH_SOURCES)
# Builds $(FW_BUILD)/NAME/NAME.elf/.hex from a core and the sources.
define fw_board
FW_$(1)_DIR := $$(FW_BUILD)/$(1)
FW_$(1)_FLAGS := $$(FW_CORE_$(2)_FLAGS) $(3)

# The sketch and the generated library are compiled in one command with
# -Werror: they are small, and this keeps the rule independent of how many
# .cpp files the generator emits.
$$(FW_$(1)_DIR)/$(1).elf: $(4) $$(FW_HEADERS) $$(FW_PROTO_SRC) $$(FW_PROTO_HDR) $$(FW_CORE_$(2)_DIR)/core.a
	@mkdir -p $$(@D)
	@test -f $$(DRONE_PROTOCOL_DIR)/src/DroneProtocol.h || { echo "missing $$(DRONE_PROTOCOL_DIR)/src/DroneProtocol.h: run the generator first" >&2; exit 1; }
	@echo "  LD    $$@"
	@$$(AVR_CXX) $$(FW_$(1)_FLAGS) $$(FW_AVR_CXXFLAGS) $$(FW_WARN) -fuse-linker-plugin -Wl,--gc-sections $$(FW_CORE_$(2)_LDFLAGS) \
	  -I$$(DRONE_PROTOCOL_DIR)/src -I$$(FW_DIR)/drone \
	  -x c++ -include Arduino.h $$(filter %.ino,$(4)) -x none $$(filter-out %.ino,$(4)) $$(FW_PROTO_SRC) \
	  $$(FW_CORE_$(2)_DIR)/core.a -lm -o $$@
$$(FW_$(1)_DIR)/$(1).hex: $$(FW_$(1)_DIR)/$(1).elf
	@$$(AVR_OBJCOPY) -O ihex -R .eeprom $$< $$@
endef

FW_DRONE_SRC := $(FW_DIR)/drone/drone.ino $(FW_SKETCH_SRC)
$(eval $(call fw_board,uno,uno,,$(FW_DRONE_SRC)))
$(eval $(call fw_board,mega,mega,,$(FW_DRONE_SRC)))
$(eval $(call fw_board,uno_ppm,uno,-DDRONE_PPM,$(FW_DRONE_SRC)))

FW_ELVES := $(FW_BUILD)/uno/uno.elf $(FW_BUILD)/mega/mega.elf $(FW_BUILD)/uno_ppm/uno_ppm.elf
FW_HEXES := $(FW_ELVES:.elf=.hex)

.PHONY: firmware firmware-uno firmware-host firmware-sim firmware-clean bench-firmware
# $(APT_STAMP) (top-level Makefile) installs the toolchain on a fresh machine.
firmware: $(APT_STAMP) $(FW_HEXES) firmware-host firmware-sim
	@$(call fw_report,uno,atmega328p)
	@$(call fw_report,uno_ppm,atmega328p)
	@$(call fw_report,mega,atmega2560)
	@echo "Flash one: make upload PORT=/dev/ttyACM0 BOARD=uno|mega|uno_ppm"

# $(call fw_report,NAME,MCU): the .hex to flash, its flash and RAM use.
fw_report = $(AVR_SIZE) -C --mcu=$(2) $(FW_BUILD)/$(1)/$(1).elf | awk -v b=$(1) -v hex=$(FW_BUILD)/$(1)/$(1).hex \
  '/^Program:/ {f = $$2; fp = $$4} /^Data:/ {d = $$2; dp = $$4} \
   END {printf "%-8s %s  flash %d B %s full), RAM %d B %s full)\n", b, hex, f, fp, d, dp}'

firmware-uno: $(FW_BUILD)/uno/uno.hex

# --- host build ---------------------------------------------------------------
FW_HOST_DIR := $(FW_BUILD)/host
FW_HOST_FLAGS := -std=c++11 -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all $(FW_WARN) -I$(FW_DIR)/host -I$(FW_DIR)/drone -I$(DRONE_PROTOCOL_DIR)/src
FW_HOST_LOGIC := $(FW_DIR)/drone/drone_app.cpp $(FW_DIR)/drone/drone_logic.cpp $(FW_DIR)/drone/drone_handlers.cpp \
                 $(FW_DIR)/drone/pulse_schedule.cpp \
                 $(FW_DIR)/host/pulse_out_host.cpp $(FW_DIR)/host/fake_arduino.cpp
FW_HOST_DEPS = $(FW_HEADERS) $(wildcard $(FW_DIR)/host/*.h) $(FW_PROTO_SRC) $(FW_PROTO_HDR)

$(FW_HOST_DIR)/virtual_drone: $(FW_DIR)/host/virtual_drone.cpp $(FW_HOST_LOGIC) $(FW_HOST_DEPS)
	@mkdir -p $(@D)
	@echo "  CXX   $@"
	@$(HOST_CXX) $(FW_HOST_FLAGS) $(filter %.cpp,$^) $(FW_PROTO_SRC) -o $@

$(FW_HOST_DIR)/pulse_schedule_test: $(FW_DIR)/host/pulse_schedule_test.cpp $(FW_DIR)/drone/pulse_schedule.cpp $(FW_HEADERS)
	@mkdir -p $(@D)
	@echo "  CXX   $@"
	@$(HOST_CXX) $(FW_HOST_FLAGS) $(filter %.cpp,$^) -o $@

# libFuzzer target over the whole logic (clang, from the toolchain stamp).
$(FW_HOST_DIR)/fuzz_drone: $(FW_DIR)/host/fuzz_drone.cpp $(FW_DIR)/drone/drone_logic.cpp $(FW_DIR)/drone/drone_handlers.cpp \
                           $(FW_HEADERS) $(FW_PROTO_HDR)
	@mkdir -p $(@D)
	@echo "  CXX   $@"
	@clang++ -std=c++11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all $(FW_WARN) \
	  -I$(FW_DIR)/drone -I$(DRONE_PROTOCOL_DIR)/src $(filter %.cpp,$^) -o $@

firmware-host: $(FW_HOST_DIR)/virtual_drone $(FW_HOST_DIR)/pulse_schedule_test $(FW_HOST_DIR)/fuzz_drone

# --- simavr harness -----------------------------------------------------------
$(FW_BUILD)/sim/drone_sim: $(FW_DIR)/sim/drone_sim.c
	@mkdir -p $(@D)
	@echo "  CC    $@"
	@$(HOST_CC) -std=gnu11 -O2 -Wall -Wextra -Werror $< $$(pkg-config --cflags --libs simavr) -o $@

firmware-sim: $(FW_BUILD)/sim/drone_sim

firmware-clean:
	rm -rf $(FW_BUILD)

-include bench/firmware/bench.mk
-include $(FW_DIR)/ide/ide.mk
