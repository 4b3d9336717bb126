// The command handlers dp::dispatch() calls (declared in drone_logic.h). Each
// either changes the state machine or sets result_ to the refusal the reply
// reports. The flight-safe policy lives here:
// - nothing moves while disarmed (not_armed) or while a sequence runs (busy);
// - ik0000 is refused while airborne (airborne): il0000, the landing routine,
//   is the way down and ends in the disarm sequence;
// - the self-test runs only disarmed (armed);
// - the laser's on/off commands set it whatever its state; disarm and the
//   failsafe switch it off (drone_logic.cpp);
// - the status query changes nothing, not even a failsafe (drone_logic.cpp).
#include "drone_limits.h"
#include "drone_logic.h"

namespace drone {

using limits::clamp16;
using limits::servo_max;
using limits::servo_min;

void Drone::stick(const dp::Command& c) {
  if (sequence_running()) {
    result_ = dp::Error::Busy;
    return;
  }
  if (!armed()) {
    result_ = dp::Error::NotArmed;
    return;
  }
  // The commanded plane gets the frame's speed; every other stick neutral.
  sticks_neutral();
  set_channel(dp::command_target(c.id), c.value);
  enter(State::Moving);
}

void Drone::on_move(const dp::Command& c) { stick(c); }
void Drone::on_turn(const dp::Command& c) { stick(c); }

void Drone::on_servo(const dp::Command& c) {
  if (state_ == State::SelfTest) {
    result_ = dp::Error::Busy;
    return;
  }
  const dp::Target target = dp::command_target(c.id);
  switch (target) {
    case dp::Target::Pan:
    case dp::Target::Tilt: {
      // Clamped to the servo's range: "sr0180" from 90 deg stops at the end.
      const int16_t delta = static_cast<int16_t>(dp::command_sense(c.id) * static_cast<int16_t>(c.value));
      uint8_t& angle = target == dp::Target::Pan ? out_.pan : out_.tilt;
      angle = static_cast<uint8_t>(clamp16(angle + delta, servo_min(target), servo_max(target)));
      break;
    }
    case dp::Target::Both:
      out_.pan = dp::SERVO_PAN_DEFAULT;
      out_.tilt = dp::SERVO_TILT_DEFAULT;
      break;
    default:
      result_ = dp::Error::Unsupported;  // a servo direction with no servo to move
      break;
  }
}

// The self-test owns the laser while it runs; a disarm or landing switches it
// off, so it cannot be switched on then.
void Drone::on_laser_toggle(const dp::Command&) {
  if (state_ == State::SelfTest || state_ == State::Disarming) {
    result_ = dp::Error::Busy;
  } else {
    set_laser(!out_.laser);
  }
}

void Drone::on_laser_on(const dp::Command&) {
  if (state_ == State::SelfTest || state_ == State::Disarming) {
    result_ = dp::Error::Busy;
  } else {
    set_laser(true);
  }
}

void Drone::on_laser_off(const dp::Command&) {
  if (state_ == State::SelfTest) {
    result_ = dp::Error::Busy;
  } else {
    set_laser(false);
  }
}

void Drone::on_arm(const dp::Command&) {
  if (state_ == State::Disarming || state_ == State::SelfTest || state_ == State::Landing) {
    result_ = dp::Error::Busy;
  } else if (!armed() && state_ != State::Arming) {
    enter(State::Arming);
  }
  // Already armed or arming: accepted, nothing to do. Re-running the arm
  // sequence in flight would cut the throttle.
}

void Drone::on_disarm(const dp::Command&) {
  // One frame never drops a flying drone: land with il0000 instead.
  if (airborne()) {
    result_ = dp::Error::Airborne;
    return;
  }
  // On the ground it always wins, even mid-sequence: the way to stop anything.
  if (state_ == State::SelfTest) end_self_test();
  if (state_ != State::Disarming) enter(State::Disarming);
}

void Drone::on_hold_altitude(const dp::Command&) {
  if (sequence_running()) {
    result_ = dp::Error::Busy;
  } else if (!armed()) {
    result_ = dp::Error::NotArmed;
  } else {
    out_.mode = dp::MODE_ALT_HOLD_US;
    enter(State::HoldAltitude);
  }
}

void Drone::on_first_test(const dp::Command&) {
  // Nudging sticks is only safe on the ground with the motors disarmed.
  if (armed()) {
    result_ = dp::Error::Armed;
  } else if (sequence_running()) {
    result_ = dp::Error::Busy;
  } else {
    enter(State::SelfTest);
  }
}

void Drone::on_land(const dp::Command&) {
  if (state_ == State::Landing || state_ == State::Disarming) {
    return;  // already on the way down: accepted, a keep-alive
  }
  if (sequence_running()) {
    result_ = dp::Error::Busy;
  } else if (!armed()) {
    result_ = dp::Error::NotArmed;
  } else {
    enter(State::Landing);
  }
}

// Accepted whatever the state: the reply's status suffix is the answer.
void Drone::on_query_status(const dp::Command&) {}

}  // namespace drone
