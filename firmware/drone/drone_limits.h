// Limits of the outputs, from the generated spec header: shared by the state
// machine (drone_logic.cpp) and the command handlers (drone_handlers.cpp).
#ifndef DRONE_LIMITS_H
#define DRONE_LIMITS_H

#include <stdint.h>

#include <DroneProtocol.h>

namespace drone {
namespace limits {

namespace dp = drone_protocol;

inline uint16_t clamp16(int32_t v, uint16_t lo, uint16_t hi) {
  return v < lo ? lo : (v > hi ? hi : static_cast<uint16_t>(v));
}

inline dp::ChannelLimits channel(dp::Target t) { return dp::channel_limits(t); }

// The failsafe throttle is the one output allowed outside Table 4: it must lie
// below the recorded minimum for the flight controller to see a radio failsafe.
static_assert(dp::FAILSAFE_THROTTLE_US < dp::THROTTLE_MIN, "failsafe throttle must be below the throttle range");

inline uint8_t servo_default(dp::Target t) { return t == dp::Target::Pan ? dp::SERVO_PAN_DEFAULT : dp::SERVO_TILT_DEFAULT; }
inline uint8_t servo_min(dp::Target t) { return t == dp::Target::Pan ? dp::SERVO_PAN_MIN : dp::SERVO_TILT_MIN; }
inline uint8_t servo_max(dp::Target t) { return t == dp::Target::Pan ? dp::SERVO_PAN_MAX : dp::SERVO_TILT_MAX; }

}  // namespace limits
}  // namespace drone

#endif
