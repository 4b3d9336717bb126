// Turns the wanted pulse widths into the edge schedule that the Timer1
// interrupt walks through. Pure code: built and checked on the host too.
#ifndef DRONE_PULSE_SCHEDULE_H
#define DRONE_PULSE_SCHEDULE_H

#include <stdint.h>

namespace pulse {

// Output lines, in the order of the pin table in pulse_out.
enum Line : uint8_t { ROLL, PITCH, THROTTLE, YAW, MODE, PAN, TILT, PPM, LINE_COUNT };
constexpr uint8_t RC_CHANNELS = 5;   // ROLL..MODE
constexpr uint8_t OUTPUTS = 7;       // ROLL..TILT: the widths the logic asks for
constexpr uint8_t NO_LINE = LINE_COUNT;  // a slot that moves no line

// Timer1 at clk/8: 2 ticks per microsecond at 16 MHz.
constexpr uint8_t TICKS_PER_US = 2;

// At the start of a slot the interrupt lowers `lower`, raises `raise`, and
// schedules the next slot `ticks` later (relative to this compare match, so
// interrupt latency never accumulates).
struct Slot {
  uint8_t lower;
  uint8_t raise;
  uint16_t ticks;
};

constexpr uint8_t MAX_SLOTS = 16;
struct Schedule {
  uint8_t count;
  Slot slot[MAX_SLOTS];
};

// One pulse per output, back to back, then a gap to fill the 50 Hz frame.
void build_parallel(const uint16_t width_us[OUTPUTS], Schedule& out);
// RC channels as one PPM-sum train on the PPM line; servos stay parallel
// and are sent during the PPM sync gap.
void build_ppm(const uint16_t width_us[OUTPUTS], Schedule& out);

}  // namespace pulse

#endif
