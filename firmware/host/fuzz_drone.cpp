// libFuzzer target for the drone logic (not just the parser): random byte
// streams with random pauses, checking after every step the safety rules the
// firmware promises. Any violation aborts, and libFuzzer keeps the input.
//
// Input: pairs of bytes (pause, serial byte). The pause byte advances the
// clock by 0..127 ms (low 7 bits); its top bit makes the transmit buffer
// "full" for that byte's replies.
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "drone_logic.h"

namespace dp = drone_protocol;

namespace {

bool tx_full = false;
bool transmit(const char*, uint8_t) { return !tx_full; }

[[noreturn]] void fail(const char* what, uint32_t now, const drone::Drone& d) {
  const drone::Outputs& o = d.outputs();
  fprintf(stderr, "violated: %s at %u ms (state %s, roll %u pitch %u throttle %u yaw %u mode %u pan %u tilt %u)\n",
          what, now, drone::state_name(d.state()), o.roll, o.pitch, o.throttle, o.yaw, o.mode, o.pan, o.tilt);
  abort();
}

bool within(uint16_t v, dp::Target t) {
  const dp::ChannelLimits l = dp::channel_limits(t);
  return v >= l.min && v <= l.max;
}

bool median(uint16_t v, dp::Target t) { return v == dp::channel_limits(t).median; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  drone::Drone d(transmit);
  uint32_t now = 0;
  d.begin(now);
  uint32_t last_frame = 0;      // when the last well-formed frame completed
  uint32_t moving_since = 0;    // when the current movement began
  bool arm_requested = false;   // an arm frame was ever accepted
  bool since_boot = true;       // disarmed ever since boot, no sequence run
  drone::State before = d.state();
  for (size_t i = 0; i + 1 < size; i += 2) {
    tx_full = (data[i] & 0x80) != 0;
    const uint32_t pause = data[i] & 0x7F;
    // Advance the clock a millisecond at a time, as loop() would.
    for (uint32_t k = 0; k < pause; ++k) {
      d.update(++now);
    }
    bool stick_frame = false;
    if (d.receive(data[i + 1], now)) {
      last_frame = now;
      const dp::Command& c = d.parser().command();
      if (c.id == dp::CommandId::Arm && d.state() == drone::State::Arming) arm_requested = true;
      stick_frame = c.category == 'm' || c.category == 't';
    }
    d.update(now);
    const drone::State s = d.state();
    // Off the ground, the only way down is the landing routine: never straight from flight to disarming.
    if (s == drone::State::Disarming && (before == drone::State::HoldAltitude || before == drone::State::Moving))
      fail("disarmed in the air", now, d);
    // A movement starts, or restarts its hold, with an accepted move or turn.
    if (s == drone::State::Moving && (before != drone::State::Moving || stick_frame)) moving_since = now;
    before = s;

    const drone::Outputs& o = d.outputs();
    // Outputs stay inside Table 4, except the failsafe throttle.
    if (!within(o.roll, dp::Target::Roll) || !within(o.pitch, dp::Target::Pitch) || !within(o.yaw, dp::Target::Yaw))
      fail("stick outside Table 4", now, d);
    // From boot until the first sequence the board holds the failsafe throttle (it may have reset in flight).
    if (s != drone::State::Disarmed) since_boot = false;
    if (since_boot && o.throttle != dp::FAILSAFE_THROTTLE_US) fail("boot without the failsafe throttle", now, d);
    if (s == drone::State::Failsafe) {
      if (o.throttle != dp::FAILSAFE_THROTTLE_US) fail("failsafe throttle", now, d);
      if (!median(o.roll, dp::Target::Roll) || !median(o.pitch, dp::Target::Pitch) || !median(o.yaw, dp::Target::Yaw))
        fail("failsafe sticks not neutral", now, d);
      if (o.laser) fail("laser on in failsafe", now, d);
    } else if (!since_boot && !within(o.throttle, dp::Target::Throttle)) {
      fail("throttle outside Table 4", now, d);
    }
    if (o.pan < dp::SERVO_PAN_MIN || o.pan > dp::SERVO_PAN_MAX || o.tilt < dp::SERVO_TILT_MIN ||
        o.tilt > dp::SERVO_TILT_MAX)
      fail("servo outside its range", now, d);
    if (o.mode != dp::MODE_STABILIZE_US && o.mode != dp::MODE_ALT_HOLD_US) fail("unknown mode pulse", now, d);
    // No valid frame for the failsafe time: failsafe, whatever else was going on.
    if (now - last_frame >= dp::FAILSAFE_TIMEOUT_MS && s != drone::State::Failsafe) fail("failsafe missed", now, d);
    // Throttle stays at its minimum whenever the drone is not flying.
    if (!since_boot &&
        (s == drone::State::Disarmed || s == drone::State::Armed || s == drone::State::Arming ||
         s == drone::State::Disarming || s == drone::State::SelfTest) &&
        o.throttle != dp::channel_limits(dp::Target::Throttle).min)
      fail("throttle above minimum on the ground", now, d);
    // Laser off through every disarm; the landing descends at the throttle's low speed.
    if (s == drone::State::Disarming && o.laser) fail("laser on while disarming", now, d);
    if (s == drone::State::Landing && (o.throttle != dp::THROTTLE_LOW || o.mode != dp::MODE_ALT_HOLD_US))
      fail("landing without alt-hold at low throttle", now, d);
    // Armed only through an arm frame (the disarm sequence reports `armed` while it runs, even from the
    // ground, to make sure the flight controller disarms); sticks move only when armed.
    if (d.armed() && s != drone::State::Disarming && !arm_requested) fail("armed without an arm frame", now, d);
    if ((s == drone::State::Moving || s == drone::State::HoldAltitude) && !d.armed()) fail("flying disarmed", now, d);
    if (s == drone::State::Disarmed && d.armed()) fail("disarmed state but armed", now, d);
    // A movement lasts at most the command timeout.
    if (s == drone::State::Moving && now - moving_since >= dp::COMMAND_TIMEOUT_MS) fail("movement outlived", now, d);
    // A movement deflects at most one stick.
    if (s == drone::State::Moving) {
      const int off = !median(o.roll, dp::Target::Roll) + !median(o.pitch, dp::Target::Pitch) +
                      !median(o.yaw, dp::Target::Yaw) + !median(o.throttle, dp::Target::Throttle);
      if (off > 1) fail("more than one stick deflected", now, d);
    }
  }
  return 0;
}
