#include "pulse_schedule.h"

#include "pins.h"

namespace pulse {

static_assert(2ul * OUTPUTS + 2 <= MAX_SLOTS, "PPM schedule needs 2 slots per RC channel plus servos and gap");
static_assert(static_cast<uint32_t>(pulse_timing::PPM_FRAME_US) * TICKS_PER_US <= 0xFFFFu,
              "a whole frame must fit one 16-bit compare step");

namespace {

void put(Schedule& s, uint8_t lower, uint8_t raise, uint32_t us) {
  Slot& slot = s.slot[s.count++];
  slot.lower = lower;
  slot.raise = raise;
  slot.ticks = static_cast<uint16_t>(us * TICKS_PER_US);
}

// Rest of the frame after `used` microseconds; never shorter than 2 ms so the
// receiver always sees a gap (only reachable with absurd widths).
uint32_t rest(uint32_t frame, uint32_t used) { return used + 2000u <= frame ? frame - used : 2000u; }

}  // namespace

void build_parallel(const uint16_t width_us[OUTPUTS], Schedule& out) {
  out.count = 0;
  uint32_t used = 0;
  for (uint8_t i = 0; i < OUTPUTS; ++i) {
    put(out, i == 0 ? NO_LINE : static_cast<uint8_t>(i - 1), i, width_us[i]);
    used += width_us[i];
  }
  put(out, OUTPUTS - 1, NO_LINE, rest(pulse_timing::PWM_FRAME_US, used));
}

void build_ppm(const uint16_t width_us[OUTPUTS], Schedule& out) {
  using pulse_timing::PPM_SEPARATOR_US;
  out.count = 0;
  uint32_t used = 0;
  // Each channel's value is the time between two separator rising edges.
  for (uint8_t i = 0; i < RC_CHANNELS; ++i) {
    put(out, NO_LINE, PPM, PPM_SEPARATOR_US);
    put(out, PPM, NO_LINE, width_us[i] - PPM_SEPARATOR_US);
    used += width_us[i];
  }
  // Closing separator, then the servo pulses inside the sync gap.
  put(out, NO_LINE, PPM, PPM_SEPARATOR_US);
  put(out, PPM, PAN, width_us[PAN]);
  put(out, PAN, TILT, width_us[TILT]);
  used += PPM_SEPARATOR_US + width_us[PAN] + width_us[TILT];
  put(out, TILT, NO_LINE, rest(pulse_timing::PPM_FRAME_US, used));
}

}  // namespace pulse
