#include "drone_logic.h"

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

uint16_t clamp16(int32_t v, uint16_t lo, uint16_t hi) {
  return v < lo ? lo : (v > hi ? hi : static_cast<uint16_t>(v));
}

dp::ChannelLimits limits(dp::Target t) { return dp::channel_limits(t); }

// The failsafe throttle is the one output allowed outside Table 4: it must lie
// below the recorded minimum for the flight controller to see a radio failsafe.
static_assert(dp::FAILSAFE_THROTTLE_US < dp::THROTTLE_MIN, "failsafe throttle must be below the throttle range");

uint8_t servo_default(dp::Target t) { return t == dp::Target::Pan ? dp::SERVO_PAN_DEFAULT : dp::SERVO_TILT_DEFAULT; }
uint8_t servo_min(dp::Target t) { return t == dp::Target::Pan ? dp::SERVO_PAN_MIN : dp::SERVO_TILT_MIN; }
uint8_t servo_max(dp::Target t) { return t == dp::Target::Pan ? dp::SERVO_PAN_MAX : dp::SERVO_TILT_MAX; }

}  // namespace

const char* state_name(State s) {
  switch (s) {
    case State::Disarmed: return "disarmed";
    case State::Arming: return "arming";
    case State::Armed: return "armed";
    case State::HoldAltitude: return "hold_altitude";
    case State::Moving: return "moving";
    case State::Disarming: return "disarming";
    case State::SelfTest: return "self_test";
    case State::Failsafe: return "failsafe";
  }
  return "?";
}

bool operator==(const Outputs& a, const Outputs& b) {
  return a.roll == b.roll && a.pitch == b.pitch && a.throttle == b.throttle && a.yaw == b.yaw &&
         a.mode == b.mode && a.pan == b.pan && a.tilt == b.tilt && a.laser == b.laser;
}

Drone::Drone(Transmit tx)
    : tx_(tx),
      parser_(),
      out_(),
      state_(State::Disarmed),
      armed_(false),
      now_ms_(0),
      state_since_ms_(0),
      last_frame_ms_(0),
      result_(dp::Error::None),
      last_parser_error_(dp::Error::None),
      test_step_(0),
      laser_before_test_(false),
      replies_dropped_(0) {}

void Drone::begin(uint32_t now_ms) {
  now_ms_ = now_ms;
  last_frame_ms_ = now_ms;
  parser_.reset();
  armed_ = false;
  out_.mode = dp::MODE_STABILIZE_US;
  out_.pan = dp::SERVO_PAN_DEFAULT;
  out_.tilt = dp::SERVO_TILT_DEFAULT;
  out_.laser = false;
  enter(State::Disarmed);
  char line[dp::REPLY_MAX_LENGTH];
  reply(line, dp::write_ready(line));
}

void Drone::reply(const char* line, uint8_t length) {
  last_parser_error_ = dp::Error::None;
  if (!tx_(line, length)) ++replies_dropped_;
}

bool Drone::receive(uint8_t byte, uint32_t now_ms) {
  now_ms_ = now_ms;
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
    reply(line, dp::write_rejected(e, line));
    last_parser_error_ = e;
  }
  return complete;
}

void Drone::execute(const dp::Command& c, uint32_t now_ms) {
  // Any well-formed frame proves the link is alive, even one refused below.
  last_frame_ms_ = now_ms;
  if (state_ == State::Failsafe) enter(armed_ ? State::Armed : State::Disarmed);
  result_ = dp::Error::None;
  dp::dispatch(c, *this);
  char line[dp::REPLY_MAX_LENGTH];
  if (result_ == dp::Error::None) {
    reply(line, dp::write_accepted(c, line));
  } else {
    reply(line, dp::write_rejected(result_, line));
  }
}

bool Drone::sequence_running() const {
  return state_ == State::Arming || state_ == State::Disarming || state_ == State::SelfTest;
}

void Drone::set_channel(dp::Target t, uint16_t us) {
  const dp::ChannelLimits l = limits(t);
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
  set_channel(dp::Target::Roll, limits(dp::Target::Roll).median);
  set_channel(dp::Target::Pitch, limits(dp::Target::Pitch).median);
  set_channel(dp::Target::Yaw, limits(dp::Target::Yaw).median);
  set_channel(dp::Target::Throttle, limits(dp::Target::Throttle).median);
}

void Drone::sticks_on_ground() {
  sticks_neutral();
  set_channel(dp::Target::Throttle, limits(dp::Target::Throttle).min);
}

void Drone::enter(State s) {
  state_ = s;
  state_since_ms_ = now_ms_;
  switch (s) {
    case State::Disarmed:
    case State::Armed:
      sticks_on_ground();
      break;
    case State::Arming:
    case State::Disarming:
      // ArduCopter only takes stick (dis)arming in a manual-throttle mode.
      out_.mode = dp::MODE_STABILIZE_US;
      sticks_on_ground();
      set_channel(dp::Target::Yaw, s == State::Arming ? limits(dp::Target::Yaw).max : limits(dp::Target::Yaw).min);
      break;
    case State::HoldAltitude:
      sticks_neutral();
      break;
    case State::Moving:
      break;  // the caller set the sticks
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
  out_.laser = false;
  char line[dp::REPLY_MAX_LENGTH];
  reply(line, dp::write_failsafe(line));
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
      const dp::ChannelLimits l = limits(s.target);
      set_channel(s.target, s.level < 0 ? l.low : s.level > 0 ? l.high : l.median);
      break;
    }
  }
}

void Drone::update(uint32_t now_ms) {
  now_ms_ = now_ms;
  const uint32_t in_state = now_ms - state_since_ms_;
  if (state_ != State::Failsafe && now_ms - last_frame_ms_ >= dp::FAILSAFE_TIMEOUT_MS) {
    // Link lost: this overrides any movement or sequence in progress.
    if (state_ == State::Arming) armed_ = false;
    if (state_ == State::SelfTest) {
      out_.pan = dp::SERVO_PAN_DEFAULT;
      out_.tilt = dp::SERVO_TILT_DEFAULT;
    }
    enter(State::Failsafe);
    return;
  }
  switch (state_) {
    case State::Moving:
      if (in_state >= dp::COMMAND_TIMEOUT_MS) enter(State::HoldAltitude);
      break;
    case State::Arming:
      if (in_state >= dp::ARMING_HOLD_MS) {
        armed_ = true;
        enter(State::Armed);
      }
      break;
    case State::Disarming:
      if (in_state >= dp::ARMING_HOLD_MS) {
        armed_ = false;
        enter(State::Disarmed);
      }
      break;
    case State::SelfTest: {
      const uint32_t step = in_state / SELF_TEST_STEP_MS;
      if (step >= SELF_TEST_STEPS) {
        out_.laser = laser_before_test_;
        enter(State::Disarmed);
      } else if (step != test_step_) {
        test_step_ = static_cast<uint8_t>(step);
        self_test_step(test_step_);
      }
      break;
    }
    default:
      break;
  }
}

// --- command handlers -------------------------------------------------------

void Drone::stick(const dp::Command& c) {
  if (sequence_running()) {
    result_ = dp::Error::Busy;
    return;
  }
  if (!armed_) {
    result_ = dp::Error::NotArmed;
    return;
  }
  // The commanded plane gets the frame's speed; every other stick neutral.
  sticks_neutral();
  set_channel(dp::command_info(c.id).target, c.value);
  enter(State::Moving);
}

void Drone::on_move(const dp::Command& c) { stick(c); }
void Drone::on_turn(const dp::Command& c) { stick(c); }

void Drone::on_servo(const dp::Command& c) {
  if (state_ == State::SelfTest) {
    result_ = dp::Error::Busy;
    return;
  }
  const dp::CommandInfo info = dp::command_info(c.id);
  const int16_t delta = static_cast<int16_t>(info.sense * static_cast<int16_t>(c.value));
  switch (info.target) {
    case dp::Target::Pan:
    case dp::Target::Tilt: {
      // Clamped to the servo's range: "sr0180" from 90 deg stops at the end.
      uint8_t& angle = info.target == dp::Target::Pan ? out_.pan : out_.tilt;
      angle = static_cast<uint8_t>(clamp16(angle + delta, servo_min(info.target), servo_max(info.target)));
      break;
    }
    case dp::Target::Both:
      out_.pan = dp::SERVO_PAN_DEFAULT;
      out_.tilt = dp::SERVO_TILT_DEFAULT;
      break;
    default:
      result_ = dp::Error::BadDirection;
      break;
  }
}

void Drone::on_laser(const dp::Command&) {
  if (state_ == State::SelfTest) {
    result_ = dp::Error::Busy;
    return;
  }
  out_.laser = !out_.laser;
}

// An init direction the firmware has no routine for.
void Drone::on_init(const dp::Command&) { result_ = dp::Error::BadDirection; }

void Drone::on_arm(const dp::Command&) {
  if (state_ == State::Disarming || state_ == State::SelfTest) {
    result_ = dp::Error::Busy;
  } else if (!armed_ && state_ != State::Arming) {
    enter(State::Arming);
  }
  // Already armed or arming: accepted, nothing to do. Re-running the arm
  // sequence in flight would cut the throttle.
}

void Drone::on_disarm(const dp::Command&) {
  // Always honoured, even mid-sequence: the way to stop anything.
  if (state_ == State::SelfTest) {
    out_.laser = laser_before_test_;
    out_.pan = dp::SERVO_PAN_DEFAULT;
    out_.tilt = dp::SERVO_TILT_DEFAULT;
  }
  if (state_ == State::Arming) armed_ = false;
  if (state_ != State::Disarming) enter(State::Disarming);
}

void Drone::on_hold_altitude(const dp::Command&) {
  if (sequence_running()) {
    result_ = dp::Error::Busy;
  } else if (!armed_) {
    result_ = dp::Error::NotArmed;
  } else {
    out_.mode = dp::MODE_ALT_HOLD_US;
    enter(State::HoldAltitude);
  }
}

void Drone::on_first_test(const dp::Command&) {
  // Nudging sticks is only safe on the ground with the motors disarmed.
  if (sequence_running() || armed_) {
    result_ = dp::Error::Busy;
  } else {
    enter(State::SelfTest);
  }
}

}  // namespace drone
