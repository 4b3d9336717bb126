// Interrupt-driven pulse generator (Timer1, normal mode, clk/8, compare A).
// The AVR implementation is pulse_out_avr.cpp; the host build supplies its
// own (firmware/host/pulse_out_host.cpp) that records the latched widths.
#ifndef DRONE_PULSE_OUT_H
#define DRONE_PULSE_OUT_H

#include <stdint.h>

#include "drone_config.h"  // DRONE_PPM: PPM-sum or parallel PWM
#include "pulse_schedule.h"

namespace pulse_out {

// Configures the pins and starts the train with these widths (microseconds,
// indexed by pulse::Line ROLL..TILT).
void begin(const uint16_t width_us[pulse::OUTPUTS]);
// Hands new widths to the interrupt, which switches over at the next frame
// boundary so no pulse is ever cut short. Returns false (and changes nothing)
// while the previous update is still waiting for that boundary: call again.
bool update(const uint16_t width_us[pulse::OUTPUTS]);

}  // namespace pulse_out

#endif
