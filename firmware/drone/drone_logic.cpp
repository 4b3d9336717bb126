#include "drone_logic.h"

#include "drone_limits.h"

// Bench builds (-DDRONE_BENCH_PARSER_PIN=n) time the parser alone: the app
// supplies this hook, which toggles a spare pin around StreamParser::feed().
#ifdef DRONE_BENCH_PARSER_PIN
void drone_bench_parser_mark();
#define DRONE_PARSER_MARK() drone_bench_parser_mark()
#else
#define DRONE_PARSER_MARK()
#endif

#ifdef __AVR__
#include <avr/pgmspace.h>
#define DRONE_FLASH PROGMEM
#else
#define DRONE_FLASH
#endif

namespace drone {

using limits::clamp16;
using limits::servo_default;
using limits::servo_max;
using limits::servo_min;

namespace {

// Constant tables live in flash on the AVR (RAM is 2 KB), in memory on the host.
uint8_t flash_byte(const void* p) {
#ifdef __AVR__
  return pgm_read_byte(p);
#else
  return *static_cast<const uint8_t*>(p);
#endif
}

// Self-test choreography: one step per SELF_TEST_STEP_MS. This is a bench
// routine of the firmware, not part of the wire protocol, so its timing is
// defined here. Throttle is never touched: it stays at its minimum.
constexpr uint16_t SELF_TEST_STEP_MS = 250;
struct TestStep {
  dp::Target target;  // None = the laser
  int8_t level;       // -1 low / minimum, 0 neutral / default, +1 high / maximum; laser: 1 on, 0 off
};
static_assert(sizeof(dp::Target) == 1, "TestStep is read from flash byte by byte");
const TestStep kSelfTest[] DRONE_FLASH = {
    {dp::Target::Pan, -1},  {dp::Target::Pan, 1},   {dp::Target::Pan, 0},  {dp::Target::Tilt, -1},
    {dp::Target::Tilt, 1},  {dp::Target::Tilt, 0},  {dp::Target::None, 1}, {dp::Target::None, 0},
    {dp::Target::None, 1},  {dp::Target::None, 0},  {dp::Target::Roll, -1}, {dp::Target::Roll, 1},
    {dp::Target::Roll, 0},  {dp::Target::Pitch, -1}, {dp::Target::Pitch, 1}, {dp::Target::Pitch, 0},
    {dp::Target::Yaw, -1},  {dp::Target::Yaw, 1},   {dp::Target::Yaw, 0},
};
constexpr uint8_t SELF_TEST_STEPS = sizeof(kSelfTest) / sizeof(kSelfTest[0]);
static_assert(sizeof(kSelfTest) / sizeof(kSelfTest[0]) < 256, "steps are counted in a uint8_t");
static_assert(static_cast<uint32_t>(SELF_TEST_STEPS) * SELF_TEST_STEP_MS <= 0xFFFFu,
              "the state machine measures its spans in 16 bits");

// Whether a command is the spec's status query (a spec without one has none):
// dispatch() calls on_query_status only for it, and builds for any spec.
struct QueryProbe {
  bool query;
  void on_query_status(const dp::Command&) { query = true; }
};
bool is_status_query(const dp::Command& c) {
  QueryProbe probe = {false};
  dp::dispatch(c, probe);
  return probe.query;
}

}  // namespace

bool operator==(const Outputs& a, const Outputs& b) {
  return a.roll == b.roll && a.pitch == b.pitch && a.throttle == b.throttle && a.yaw == b.yaw &&
         a.mode == b.mode && a.pan == b.pan && a.tilt == b.tilt && a.laser == b.laser;
}

void Drone::begin(uint32_t now_ms) {
  now_ms_ = static_cast<uint16_t>(now_ms);
  last_frame_ms_ = static_cast<uint16_t>(now_ms);
  parser_.reset();
  out_.mode = dp::MODE_STABILIZE_US;
  out_.pan = dp::SERVO_PAN_DEFAULT;
  out_.tilt = dp::SERVO_TILT_DEFAULT;
  out_.laser = false;
  enter(State::Disarmed);
  // A boot may be a reset in flight (DTR when the Pi reopens the port, a
  // brown-out): throttle minimum in Stabilize would drop the drone. Below
  // FS_THR_VALUE the flight controller lands instead (and merely disarms when
  // already on the ground). The first arming sequence raises it to minimum.
  out_.throttle = dp::FAILSAFE_THROTTLE_US;
  char line[dp::REPLY_MAX_LENGTH];
  reply(line, dp::write_ready(line));
}

void Drone::reply(const char* line, uint8_t length) {
  last_parser_error_ = dp::Error::None;
  if (!tx_(line, length)) ++replies_dropped_;
}

bool Drone::receive(uint8_t byte, uint32_t now_ms) {
  now_ms_ = static_cast<uint16_t>(now_ms);
  char line[dp::REPLY_MAX_LENGTH];
  DRONE_PARSER_MARK();
  const bool complete = parser_.feed(byte, now_ms);
  DRONE_PARSER_MARK();
  if (complete) {
    execute(parser_.command(), now_ms);
  } else if (parser_.last_error() != dp::Error::None && parser_.last_error() != last_parser_error_) {
    // A malformed or timed-out frame: tell the Pi, change nothing else. It
    // does not count as a sign of life for the failsafe. A burst of garbage
    // is answered once per kind of error (the parser counts every byte), so
    // noise cannot fill the transmit buffer ahead of real replies.
    const dp::Error e = parser_.last_error();
    reply(line, dp::write_rejected(e, state_, out_.laser, line));
    last_parser_error_ = e;
  }
  return complete;
}

void Drone::execute(const dp::Command& c, uint32_t now_ms) {
  // Any well-formed frame proves the link is alive, even one refused below.
  last_frame_ms_ = static_cast<uint16_t>(now_ms);
  // The failsafe disarmed the drone: a new arming sequence is needed. The
  // status query reports the failsafe instead of ending it.
  if (state_ == State::Failsafe && !is_status_query(c)) enter(State::Disarmed);
  result_ = dp::Error::None;
  // A command this firmware has no handler for yet is answered `unsupported`.
  const dp::Error unhandled = dp::dispatch(c, *this);
  if (unhandled != dp::Error::None) result_ = unhandled;
  // Every reply reports the state and laser the command left.
  char line[dp::REPLY_MAX_LENGTH];
  if (result_ == dp::Error::None) {
    reply(line, dp::write_accepted(c, state_, out_.laser, line));
  } else {
    reply(line, dp::write_rejected(result_, state_, out_.laser, line));
  }
}

bool Drone::sequence_running() const {
  return state_ == State::Arming || state_ == State::Disarming || state_ == State::SelfTest ||
         state_ == State::Landing;
}

// Off the ground: a disarm there would drop the drone.
bool Drone::airborne() const {
  return state_ == State::HoldAltitude || state_ == State::Moving || state_ == State::Landing;
}

void Drone::set_laser(bool on) { out_.laser = on; }

void Drone::set_channel(dp::Target t, uint16_t us) {
  const dp::ChannelLimits l = limits::channel(t);
  const uint16_t v = clamp16(us, l.min, l.max);  // Table 4 extremes, whatever asked
  switch (t) {
    case dp::Target::Roll: out_.roll = v; break;
    case dp::Target::Pitch: out_.pitch = v; break;
    case dp::Target::Throttle: out_.throttle = v; break;
    case dp::Target::Yaw: out_.yaw = v; break;
    default: break;
  }
}

void Drone::sticks_neutral() {
  // Table 4's medians (inside the extremes by construction: no clamp needed).
  out_.roll = dp::ROLL_MEDIAN;
  out_.pitch = dp::PITCH_MEDIAN;
  out_.yaw = dp::YAW_MEDIAN;
  out_.throttle = dp::THROTTLE_MEDIAN;
}

void Drone::sticks_on_ground() {
  sticks_neutral();
  out_.throttle = dp::THROTTLE_MIN;
}

void Drone::enter(State s) {
  state_ = s;
  state_since_ms_ = now_ms_;
  switch (s) {
    case State::Disarmed:
    case State::Armed:
      sticks_on_ground();
      break;
    case State::Disarming:
      set_laser(false);  // laser off is part of every disarm
      // fall through
    case State::Arming:
      // ArduCopter only takes stick (dis)arming in a manual-throttle mode.
      out_.mode = dp::MODE_STABILIZE_US;
      sticks_on_ground();
      out_.yaw = s == State::Arming ? dp::YAW_MAX : dp::YAW_MIN;
      break;
    case State::HoldAltitude:
      sticks_neutral();
      break;
    case State::Moving:
      break;  // the caller set the sticks
    case State::Landing:
      // Descend in alt-hold: the throttle below its median asks the flight
      // controller for a slow climb-rate down.
      out_.mode = dp::MODE_ALT_HOLD_US;
      sticks_neutral();
      out_.throttle = dp::THROTTLE_LOW;
      break;
    case State::SelfTest:
      sticks_on_ground();
      laser_before_test_ = out_.laser;
      test_step_ = 0;
      self_test_step(0);
      break;
    case State::Failsafe:
      enter_failsafe();
      break;
  }
}

void Drone::enter_failsafe() {
  sticks_neutral();
  // Deliberately below Table 4's minimum: the flight controller reads it as
  // a radio failsafe (below its FS_THR_VALUE) and lands on its own.
  out_.throttle = dp::FAILSAFE_THROTTLE_US;
  set_laser(false);
  // The flight controller lands and disarms on its own; this firmware counts
  // the drone disarmed from here on (a new arming sequence is needed).
  char line[dp::REPLY_MAX_LENGTH];
  reply(line, dp::write_failsafe(state_, out_.laser, line));
}

// The servos back to their defaults, the laser as it was before the test.
void Drone::end_self_test() {
  out_.pan = dp::SERVO_PAN_DEFAULT;
  out_.tilt = dp::SERVO_TILT_DEFAULT;
  set_laser(laser_before_test_);
}

void Drone::self_test_step(uint8_t step) {
  TestStep s;
  s.target = static_cast<dp::Target>(flash_byte(&kSelfTest[step].target));
  s.level = static_cast<int8_t>(flash_byte(&kSelfTest[step].level));
  switch (s.target) {
    case dp::Target::None:
      out_.laser = s.level != 0;
      break;
    case dp::Target::Pan:
    case dp::Target::Tilt: {
      const uint8_t deg = s.level < 0 ? servo_min(s.target) : s.level > 0 ? servo_max(s.target) : servo_default(s.target);
      (s.target == dp::Target::Pan ? out_.pan : out_.tilt) = deg;
      break;
    }
    default: {
      const dp::ChannelLimits l = limits::channel(s.target);
      set_channel(s.target, s.level < 0 ? l.low : s.level > 0 ? l.high : l.median);
      break;
    }
  }
}

void Drone::update(uint32_t now_ms) {
  now_ms_ = static_cast<uint16_t>(now_ms);
  const uint16_t in_state = static_cast<uint16_t>(now_ms_ - state_since_ms_);
  if (state_ != State::Failsafe && static_cast<uint16_t>(now_ms_ - last_frame_ms_) >= dp::FAILSAFE_TIMEOUT_MS) {
    // Link lost: this overrides any movement or sequence in progress.
    if (state_ == State::SelfTest) end_self_test();
    parser_.expire();  // a partial frame from before the silence never completes after it
    enter(State::Failsafe);
    return;
  }
  switch (state_) {
    case State::Moving:
      if (in_state >= dp::COMMAND_TIMEOUT_MS) enter(State::HoldAltitude);
      break;
    case State::Arming:
      if (in_state >= dp::ARMING_HOLD_MS) enter(State::Armed);
      break;
    case State::Disarming:
      if (in_state >= dp::ARMING_HOLD_MS) enter(State::Disarmed);
      break;
    case State::Landing:
      if (in_state >= dp::LANDING_MS) enter(State::Disarming);
      break;
    case State::SelfTest: {
      // The next step is due (no division: a 32-bit one costs flash and time).
      if (in_state >= static_cast<uint16_t>((test_step_ + 1u) * SELF_TEST_STEP_MS)) {
        if (++test_step_ >= SELF_TEST_STEPS) {
          end_self_test();
          enter(State::Disarmed);
        } else {
          self_test_step(test_step_);
        }
      }
      break;
    }
    default:
      break;
  }
}

}  // namespace drone
