// Calls the drone logic directly with commands the parser would never let
// through (values beyond Table 4), to check the second line of defence: the
// outputs are clamped to the recorded extremes whatever a handler is given.
// Prints one JSON object; test_firmware_logic.py checks it.
#include <stdio.h>

#include "drone_logic.h"

namespace dp = drone_protocol;

namespace {
bool sink(const char*, uint8_t) { return true; }

dp::Command forged(dp::CommandId id, uint16_t value) {
  const dp::CommandInfo info = dp::command_info(id);
  dp::Command c;
  c.id = id;
  c.category = info.category;
  c.direction = info.direction;
  c.value = value;
  return c;
}
}  // namespace

int main() {
  drone::Drone d(sink);
  d.begin(0);
  uint32_t t = 1;
  // Arm through the real byte path, with keep-alive frames (servo_reset)
  // so that the failsafe does not cut the arming hold short.
  const char* arm = "ia0000";
  for (const char* p = arm; *p; ++p) d.receive(static_cast<uint8_t>(*p), t);
  for (; t <= dp::ARMING_HOLD_MS + 1; ++t) {
    if (t % 500 == 0) {
      for (const char* p = "sx0000"; *p; ++p) d.receive(static_cast<uint8_t>(*p), t);
    }
    d.update(t);
  }
  printf("{\"armed\":%s", d.armed() ? "true" : "false");
  struct Case {
    const char* name;
    dp::CommandId id;
    uint16_t value;
  } cases[] = {
      {"pitch_high", dp::CommandId::MoveForward, 65000}, {"pitch_low", dp::CommandId::MoveBackward, 1},
      {"roll_high", dp::CommandId::MoveRight, 5000},     {"roll_low", dp::CommandId::MoveLeft, 0},
      {"throttle_high", dp::CommandId::MoveUp, 3000},    {"throttle_low", dp::CommandId::MoveDown, 2},
      {"yaw_high", dp::CommandId::TurnRight, 9999},      {"yaw_low", dp::CommandId::TurnLeft, 3},
  };
  for (const Case& c : cases) {
    dp::dispatch(forged(c.id, c.value), d);
    const drone::Outputs& o = d.outputs();
    printf(",\"%s\":{\"roll\":%u,\"pitch\":%u,\"throttle\":%u,\"yaw\":%u}", c.name, o.roll, o.pitch, o.throttle,
           o.yaw);
  }
  dp::dispatch(forged(dp::CommandId::ServoRight, 900), d);
  dp::dispatch(forged(dp::CommandId::ServoDown, 900), d);
  printf(",\"servo_far\":{\"pan\":%u,\"tilt\":%u}}\n", d.outputs().pan, d.outputs().tilt);
  return 0;
}
