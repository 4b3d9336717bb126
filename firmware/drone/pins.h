// The drone firmware's pins, from the spec's wiring (DroneProtocolWiring.h).
// Pulse-train timing lives here too: it is a property of the RC receiver
// interface, not of the serial protocol (which comes from DroneProtocol.h).
#ifndef DRONE_PINS_H
#define DRONE_PINS_H

#include <DroneProtocolWiring.h>
#include <stdint.h>

#include "pulse_schedule.h"

namespace pins {

// The pin numbers are the spec's (`wiring:` in spec/drone.yaml, generated into DroneProtocolWiring.h).
namespace w = drone_protocol::wiring;
// Parallel-PWM RC outputs, in ArduCopter's input order (ch1..ch5).
constexpr uint8_t ROLL = w::ROLL_PIN;
constexpr uint8_t PITCH = w::PITCH_PIN;
constexpr uint8_t THROTTLE = w::THROTTLE_PIN;
constexpr uint8_t YAW = w::YAW_PIN;
constexpr uint8_t MODE = w::MODE_PIN;
// Camera/laser pan-tilt servos.
constexpr uint8_t PAN = w::PAN_PIN;
constexpr uint8_t TILT = w::TILT_PIN;
// Laser (on the Uno, pin 13 is also the on-board LED, which helps on the bench).
constexpr uint8_t LASER = w::LASER_PIN;
// PPM-sum build (DRONE_PPM, see drone_config.h): the five RC channels leave on this one pin, which may
// replace an RC output; the other RC pins stay low.
constexpr uint8_t PPM = w::PPM_PIN;

// The PPM train carries the RC channels in pulse::Line order, so the spec's input order must be that one.
static_assert(w::RC_INPUT_COUNT == pulse::RC_CHANNELS, "the spec wires another number of RC outputs");
static_assert(w::ROLL_INPUT == pulse::ROLL + 1 && w::PITCH_INPUT == pulse::PITCH + 1 &&
                  w::THROTTLE_INPUT == pulse::THROTTLE + 1 && w::YAW_INPUT == pulse::YAW + 1 &&
                  w::MODE_INPUT == pulse::MODE + 1,
              "wiring.rc_inputs must list roll, pitch, throttle, yaw, mode: the firmware's channel order");

}  // namespace pins

namespace pulse_timing {

// 50 Hz frame for parallel PWM (what APM-era boards and servos expect).
constexpr uint16_t PWM_FRAME_US = 20000;
// PPM-sum: 22.5 ms frame, 300 us separator pulses (the common Futaba-style
// convention that ArduPilot's PPM decoder accepts).
constexpr uint16_t PPM_FRAME_US = 22500;
constexpr uint16_t PPM_SEPARATOR_US = 300;
// Servo calibration: 0..180 degrees map linearly onto this pulse range
// (the Arduino Servo library's defaults, so existing servo setups agree).
constexpr uint16_t SERVO_MIN_US = 544;
constexpr uint16_t SERVO_MAX_US = 2400;
constexpr uint16_t SERVO_FULL_SCALE_DEG = 180;

}  // namespace pulse_timing

#endif
