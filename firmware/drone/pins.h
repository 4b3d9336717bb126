// Default wiring of the drone firmware: the one place that names Arduino pins.
// Pulse-train timing lives here too: it is a property of the RC receiver
// interface, not of the serial protocol (which comes from DroneProtocol.h).
#ifndef DRONE_PINS_H
#define DRONE_PINS_H

#include <stdint.h>

namespace pins {

// Parallel-PWM RC outputs, in ArduCopter's input order (ch1..ch5).
constexpr uint8_t ROLL = 2;
constexpr uint8_t PITCH = 3;
constexpr uint8_t THROTTLE = 4;
constexpr uint8_t YAW = 5;
constexpr uint8_t MODE = 6;
// Camera/laser pan-tilt servos.
constexpr uint8_t PAN = 9;
constexpr uint8_t TILT = 10;
// Laser (the Uno's on-board LED shares this pin, which helps on the bench).
constexpr uint8_t LASER = 13;
// PPM-sum build (-DDRONE_PPM): the five RC channels leave on this one pin,
// which replaces the ROLL output; the other RC pins stay low.
constexpr uint8_t PPM = ROLL;

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
