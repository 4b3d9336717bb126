// The drone's behaviour, free of any hardware: bytes and the time go in,
// wanted outputs and reply lines come out. The same code runs on the AVR and
// in the host build; every protocol number comes from DroneProtocol.h.
#ifndef DRONE_LOGIC_H
#define DRONE_LOGIC_H

#include <stdint.h>

#include <DroneProtocol.h>

// Kept out of line on purpose: link-time inlining of these into loop() made
// the Uno build about 200 bytes bigger.
#define DRONE_NOINLINE __attribute__((noinline))

namespace drone {

namespace dp = drone_protocol;

// What the outputs are doing: the spec's status states (dp::State, generated
// from spec/drone.yaml, so every reply reports exactly this). One state
// machine: sequences (arming, landing, disarming, self-test) are states, so
// nothing ever waits in delay().
//   disarmed       throttle minimum, other sticks neutral (from boot until
//                  the first sequence: the failsafe throttle)
//   arming         throttle minimum + yaw full right for ARMING_HOLD_MS
//   armed          armed, throttle minimum (on the ground)
//   hold_altitude  sticks neutral, throttle median, mode alt-hold
//   moving         one stick deflected until COMMAND_TIMEOUT_MS passes
//   landing        alt-hold, throttle at its low speed for LANDING_MS
//   disarming      throttle minimum + yaw full left for ARMING_HOLD_MS
//   self_test      servo sweep, laser blinks, stick nudges; throttle minimum
//   failsafe       no valid frame for FAILSAFE_TIMEOUT_MS; disarmed
typedef dp::State State;
inline const char* state_name(State s) { return dp::state_name(s); }

struct Outputs {
  uint16_t roll, pitch, throttle, yaw, mode;  // RC pulse widths, us
  uint8_t pan, tilt;                          // servo angles, degrees
  bool laser;
};
bool operator==(const Outputs& a, const Outputs& b);
inline bool operator!=(const Outputs& a, const Outputs& b) { return !(a == b); }

class Drone {
 public:
  // Sends one reply line; returns false if it does not fit the transmit
  // buffer right now. The reply is then dropped (and counted), never waited on.
  typedef bool (*Transmit)(const char* data, uint8_t length);

  // constexpr: the global drone is initialised statically, with no
  // constructor code at start-up.
  explicit constexpr Drone(Transmit tx)
      : tx_(tx),
        parser_(),
        out_(),
        state_(State::Disarmed),
        now_ms_(0),
        state_since_ms_(0),
        last_frame_ms_(0),
        result_(dp::Error::None),
        last_parser_error_(dp::Error::None),
        test_step_(0),
        laser_before_test_(false),
        replies_dropped_(0) {}

  // Times are the millis() clock. The state machine keeps its low 16 bits: every span it measures (the
  // longest is the self-test, under 5 s) is exact as long as update() runs at least every 65.5 s, which the
  // sketch's loop() does every millisecond; 16-bit arithmetic saves about 200 bytes of AVR flash over 32.
  void begin(uint32_t now_ms);                 // boot: safe outputs, ready line
  // One serial byte; returns true when it completed a frame (which may have
  // changed the outputs).
  DRONE_NOINLINE bool receive(uint8_t byte, uint32_t now_ms);
  DRONE_NOINLINE void update(uint32_t now_ms);                // timers and sequences

  const Outputs& outputs() const { return out_; }
  State state() const { return state_; }
  // The motors may spin (the spec's `armed` flag of the state).
  bool armed() const { return dp::state_armed(state_); }
  uint16_t replies_dropped() const { return replies_dropped_; }
  const dp::StreamParser& parser() const { return parser_; }

  // Handlers called by dp::dispatch() (drone_handlers.cpp). Move, turn and
  // servo are handled per category from the command's target, so a direction
  // added to the spec needs no edit here; a command with no handler at all is
  // answered `unsupported` by the generated dispatch.
  void on_move(const dp::Command& c);
  void on_turn(const dp::Command& c);
  void on_servo(const dp::Command& c);
  void on_laser_toggle(const dp::Command& c);
  void on_laser_on(const dp::Command& c);
  void on_laser_off(const dp::Command& c);
  void on_arm(const dp::Command& c);
  void on_disarm(const dp::Command& c);
  void on_hold_altitude(const dp::Command& c);
  void on_first_test(const dp::Command& c);
  void on_land(const dp::Command& c);
  void on_query_status(const dp::Command& c);

 private:
  DRONE_NOINLINE void execute(const dp::Command& c, uint32_t now_ms);
  void stick(const dp::Command& c);
  void set_laser(bool on);
  void set_channel(dp::Target t, uint16_t us);
  void sticks_neutral();
  void sticks_on_ground();
  DRONE_NOINLINE void enter(State s);
  void enter_failsafe();
  void end_self_test();
  void self_test_step(uint8_t step);
  bool sequence_running() const;
  bool airborne() const;
  void reply(const char* line, uint8_t length);

  Transmit tx_;
  dp::StreamParser parser_;
  Outputs out_;
  State state_;
  uint16_t now_ms_;          // low 16 bits of the clock, as the spans below
  uint16_t state_since_ms_;
  uint16_t last_frame_ms_;
  dp::Error result_;             // set by the handler that dispatch() picked
  dp::Error last_parser_error_;  // the last reply, if it reported this parser error
  uint8_t test_step_;
  bool laser_before_test_;
  uint16_t replies_dropped_;
};

}  // namespace drone

#endif
