// The drone's behaviour, free of any hardware: bytes and the time go in,
// wanted outputs and reply lines come out. The same code runs on the AVR and
// in the host build; every protocol number comes from DroneProtocol.h.
#ifndef DRONE_LOGIC_H
#define DRONE_LOGIC_H

#include <stdint.h>

#include <DroneProtocol.h>

namespace drone {

namespace dp = drone_protocol;

// What the outputs are doing. One state machine: sequences (arming,
// disarming, self-test) are states, so nothing ever waits in delay().
enum class State : uint8_t {
  Disarmed,      // throttle minimum, other sticks neutral
  Arming,        // throttle minimum + yaw full right for ARMING_HOLD_MS
  Armed,         // armed, throttle minimum (on the ground)
  HoldAltitude,  // sticks neutral, throttle median, mode alt-hold
  Moving,        // one stick deflected until COMMAND_TIMEOUT_MS passes
  Disarming,     // throttle minimum + yaw full left for ARMING_HOLD_MS
  SelfTest,      // servo sweep, laser blinks, stick nudges; throttle minimum
  Failsafe,      // no valid frame for FAILSAFE_TIMEOUT_MS
};
const char* state_name(State s);

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

  explicit Drone(Transmit tx);

  void begin(uint32_t now_ms);                 // boot: safe outputs, ready line
  // One serial byte; returns true when it completed a frame (which may have
  // changed the outputs).
  bool receive(uint8_t byte, uint32_t now_ms);
  void update(uint32_t now_ms);                // timers and sequences

  const Outputs& outputs() const { return out_; }
  State state() const { return state_; }
  bool armed() const { return armed_; }
  uint16_t replies_dropped() const { return replies_dropped_; }
  const dp::StreamParser& parser() const { return parser_; }

  // Handlers called by dp::dispatch(). Categories are handled generically
  // from command_info(), so a direction added to the spec needs no edit here.
  void on_move(const dp::Command& c);
  void on_turn(const dp::Command& c);
  void on_servo(const dp::Command& c);
  void on_laser(const dp::Command& c);
  void on_init(const dp::Command& c);
  void on_arm(const dp::Command& c);
  void on_disarm(const dp::Command& c);
  void on_hold_altitude(const dp::Command& c);
  void on_first_test(const dp::Command& c);

 private:
  void execute(const dp::Command& c, uint32_t now_ms);
  void stick(const dp::Command& c);
  void set_channel(dp::Target t, uint16_t us);
  void sticks_neutral();
  void sticks_on_ground();
  void enter(State s);
  void enter_failsafe();
  void self_test_step(uint8_t step);
  bool sequence_running() const;
  void reply(const char* line, uint8_t length);

  Transmit tx_;
  dp::StreamParser parser_;
  Outputs out_;
  State state_;
  bool armed_;
  uint32_t now_ms_;
  uint32_t state_since_ms_;
  uint32_t last_frame_ms_;
  dp::Error result_;             // set by the handler that dispatch() picked
  dp::Error last_parser_error_;  // the last reply, if it reported this parser error
  uint8_t test_step_;
  bool laser_before_test_;
  uint16_t replies_dropped_;
};

}  // namespace drone

#endif
