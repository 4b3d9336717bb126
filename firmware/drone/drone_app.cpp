#include "drone_app.h"

#include <Arduino.h>
#ifdef __AVR__
#include <avr/sleep.h>
#endif

#include "pin_io.h"
#include "pins.h"
#include "pulse_out.h"
#include "serial_link.h"

#ifdef DRONE_BENCH_PARSER_PIN
void drone_bench_parser_mark();  // called by drone_logic.cpp around the parser
#endif

namespace drone_app {

namespace {

// The longest pulses the protocol allows must fit one output frame with a
// gap to spare, or the generator would stretch the frame (pulse_schedule.cpp).
constexpr uint32_t MODE_MAX_US =
    drone::dp::MODE_ALT_HOLD_US > drone::dp::MODE_STABILIZE_US ? drone::dp::MODE_ALT_HOLD_US
                                                               : drone::dp::MODE_STABILIZE_US;
constexpr uint32_t RC_MAX_SUM_US = static_cast<uint32_t>(drone::dp::ROLL_MAX) + drone::dp::PITCH_MAX +
                                   drone::dp::THROTTLE_MAX + drone::dp::YAW_MAX + MODE_MAX_US;
static_assert(RC_MAX_SUM_US + 2u * pulse_timing::SERVO_MAX_US + 2000u <= pulse_timing::PWM_FRAME_US,
              "the widest parallel-PWM pulses no longer fit a 50 Hz frame");
static_assert(RC_MAX_SUM_US + pulse_timing::PPM_SEPARATOR_US + 2u * pulse_timing::SERVO_MAX_US + 3000u <=
                  pulse_timing::PPM_FRAME_US,
              "the widest PPM channels no longer leave a sync gap");

// Never blocks the loop on a slow or absent reader: a reply that does not fit is dropped instead.
drone::Drone the_drone(serial_link::write);
drone::Outputs applied;  // the outputs the pins and pulse generator were last given
uint16_t pending_widths[pulse::OUTPUTS];
bool widths_pending = false;  // pending_widths not yet taken by the generator
bool laser_written = false;
uint32_t updated_ms = 0;  // when update() last ran

// Degrees to microseconds by multiply-and-shift: a 32-bit division costs
// ~600 cycles on the AVR, this ~40. Checked equal to exact rounding for every
// angle at compile time.
constexpr uint32_t SERVO_SPAN_US = pulse_timing::SERVO_MAX_US - pulse_timing::SERVO_MIN_US;
constexpr uint32_t SERVO_SCALE =
    ((SERVO_SPAN_US << 16) + pulse_timing::SERVO_FULL_SCALE_DEG / 2) / pulse_timing::SERVO_FULL_SCALE_DEG;
constexpr uint16_t servo_us_fast(uint32_t deg) {
  return static_cast<uint16_t>(pulse_timing::SERVO_MIN_US + ((deg * SERVO_SCALE + 0x8000u) >> 16));
}
constexpr uint16_t servo_us_exact(uint32_t deg) {
  return static_cast<uint16_t>(pulse_timing::SERVO_MIN_US +
                               (deg * SERVO_SPAN_US + pulse_timing::SERVO_FULL_SCALE_DEG / 2) /
                                   pulse_timing::SERVO_FULL_SCALE_DEG);
}
constexpr bool servo_us_exact_from(uint32_t deg) {
  return deg > pulse_timing::SERVO_FULL_SCALE_DEG ||
         (servo_us_fast(deg) == servo_us_exact(deg) && servo_us_exact_from(deg + 1));
}
static_assert(servo_us_exact_from(0), "servo_us_fast must round like the exact formula");
// Past the full scale a degree would pulse past SERVO_MAX_US: the generator refuses such a spec, and this refuses a
// library generated without that check.
static_assert(drone_protocol::SERVO_PAN_MAX <= pulse_timing::SERVO_FULL_SCALE_DEG &&
                  drone_protocol::SERVO_TILT_MAX <= pulse_timing::SERVO_FULL_SCALE_DEG,
              "a servo range past the full scale would pulse past SERVO_MAX_US");

uint16_t servo_us(uint8_t deg) { return servo_us_fast(deg); }

// Not inlined: setup() and apply_outputs() share one copy.
__attribute__((noinline)) void widths_of(const drone::Outputs& o, uint16_t w[pulse::OUTPUTS]) {
  w[pulse::ROLL] = o.roll;
  w[pulse::PITCH] = o.pitch;
  w[pulse::THROTTLE] = o.throttle;
  w[pulse::YAW] = o.yaw;
  w[pulse::MODE] = o.mode;
  w[pulse::PAN] = servo_us(o.pan);
  w[pulse::TILT] = servo_us(o.tilt);
}

// Hands the latest widths to the pulse generator; it takes them at its next
// frame boundary, so this may have to be retried (cheaply) on later passes.
void flush_widths() {
  if (pulse_out::update(pending_widths)) widths_pending = false;
}

void apply_outputs() {
  const drone::Outputs& o = the_drone.outputs();
  if (!(o == applied)) {
    applied = o;
    if (o.laser != laser_written) {
      pin_io::flip_to(pins::LASER, o.laser);
      laser_written = o.laser;
    }
    widths_of(o, pending_widths);  // the newest widths always win
    widths_pending = true;
  }
  if (widths_pending) flush_widths();
}

// Sleep until the next interrupt when no byte waits: a received byte, the
// millis() tick (every 1.024 ms) or a pulse edge wakes the loop again, so no
// deadline slips by more than a tick. Saves power, and lets the simulator
// skip the idle time. SEI's one-instruction delay makes check-then-sleep
// race-free: a byte arriving after the check still wakes the CPU.
void idle() {
#ifdef __AVR__
  set_sleep_mode(SLEEP_MODE_IDLE);
  cli();
  if (serial_link::available() == 0) {
    sleep_enable();
    sei();
    sleep_cpu();
    sleep_disable();
  }
  sei();
#endif
}

}  // namespace

const drone::Drone& logic() { return the_drone; }

#if defined(DRONE_BENCH_PIN) || defined(DRONE_BENCH_PARSER_PIN)
#ifdef DRONE_BENCH_PIN
#define DRONE_MARK_PIN DRONE_BENCH_PIN
#else
#define DRONE_MARK_PIN DRONE_BENCH_PARSER_PIN
#endif
// Bench builds mark work on a spare pin, which the simulator times. Toggling
// through PINx is one store: cheap, and safe beside the pulse interrupt
// writing the same port.
volatile uint8_t* mark_reg;
uint8_t mark_mask;
void bench_mark() { *mark_reg = mark_mask; }
#endif

void setup() {
  pin_io::output_low(pins::LASER);
  laser_written = false;
  widths_pending = false;
  updated_ms = millis();
#ifdef DRONE_MARK_PIN
  pin_io::output_low(DRONE_MARK_PIN);
  mark_reg = portInputRegister(digitalPinToPort(DRONE_MARK_PIN));
  mark_mask = digitalPinToBitMask(DRONE_MARK_PIN);
  // Calibration: empty marked spans, so the bench can subtract the cost of
  // the marking itself.
  for (uint8_t i = 0; i < 8; ++i) {
#ifdef DRONE_BENCH_PARSER_PIN
    drone_bench_parser_mark();
    drone_bench_parser_mark();
#else
    bench_mark();
    bench_mark();
#endif
  }
#endif
  serial_link::begin();
  the_drone.begin(millis());
  applied = the_drone.outputs();
  uint16_t w[pulse::OUTPUTS];
  widths_of(applied, w);
  pulse_out::begin(w);
}

void loop() {
  const uint32_t now = millis();
#ifdef DRONE_BENCH_PIN
  const bool busy = serial_link::available() > 0;
  if (busy) bench_mark();
#endif
  // Bounded so timers and outputs are served even under a byte flood.
  bool framed = false;
  for (uint8_t n = 0; n < 64 && serial_link::available() > 0; ++n) {
    framed |= the_drone.receive(serial_link::read(), now);
  }
  // Timers only move when millis() does, outputs only after a frame or a
  // timer: a byte in the middle of a frame costs little more than the parser.
  if (framed || now != updated_ms) {
    the_drone.update(now);
    updated_ms = now;
    apply_outputs();
  } else if (widths_pending) {
    flush_widths();
  }
#ifdef DRONE_BENCH_PIN
  if (busy) bench_mark();
#endif
  idle();
}

}  // namespace drone_app

#ifdef DRONE_BENCH_PARSER_PIN
void drone_bench_parser_mark() { drone_app::bench_mark(); }
#endif
