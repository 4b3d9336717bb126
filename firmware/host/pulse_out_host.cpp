// Host stand-in for the Timer1 generator: builds the same schedule (so its
// code is exercised) and latches the widths immediately.
#include "pulse_out.h"

namespace pulse_out {

namespace {
pulse::Schedule g_schedule;
}

void begin(const uint16_t width_us[pulse::OUTPUTS]) { update(width_us); }

bool update(const uint16_t width_us[pulse::OUTPUTS]) {
#ifdef DRONE_PPM
  pulse::build_ppm(width_us, g_schedule);
#else
  pulse::build_parallel(width_us, g_schedule);
#endif
  return true;
}

}  // namespace pulse_out
