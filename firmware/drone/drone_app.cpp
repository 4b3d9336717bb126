#include "drone_app.h"

#include <Arduino.h>

#include "pins.h"
#include "pulse_out.h"

namespace drone_app {

namespace {

bool transmit(const char* data, uint8_t length) {
  // Never block the loop on a slow or absent reader: drop the reply instead.
  if (Serial.availableForWrite() < static_cast<int>(length)) return false;
  Serial.write(reinterpret_cast<const uint8_t*>(data), length);
  return true;
}

drone::Drone the_drone(transmit);
uint16_t sent_widths[pulse::OUTPUTS];
bool widths_pending = false;
bool laser_written = false;

uint16_t servo_us(uint8_t deg) {
  using namespace pulse_timing;
  return static_cast<uint16_t>(SERVO_MIN_US + (static_cast<uint32_t>(deg) * (SERVO_MAX_US - SERVO_MIN_US) +
                                               SERVO_FULL_SCALE_DEG / 2) /
                                                  SERVO_FULL_SCALE_DEG);
}

void widths_of(const drone::Outputs& o, uint16_t w[pulse::OUTPUTS]) {
  w[pulse::ROLL] = o.roll;
  w[pulse::PITCH] = o.pitch;
  w[pulse::THROTTLE] = o.throttle;
  w[pulse::YAW] = o.yaw;
  w[pulse::MODE] = o.mode;
  w[pulse::PAN] = servo_us(o.pan);
  w[pulse::TILT] = servo_us(o.tilt);
}

void apply_outputs() {
  const drone::Outputs& o = the_drone.outputs();
  if (o.laser != laser_written) {
    digitalWrite(pins::LASER, o.laser ? HIGH : LOW);
    laser_written = o.laser;
  }
  uint16_t w[pulse::OUTPUTS];
  widths_of(o, w);
  bool same = true;
  for (uint8_t i = 0; i < pulse::OUTPUTS; ++i) same = same && w[i] == sent_widths[i];
  // If the generator has not latched the last update yet, try again on the
  // next pass; the newest widths always win.
  if ((!same || widths_pending) && pulse_out::update(w)) {
    for (uint8_t i = 0; i < pulse::OUTPUTS; ++i) sent_widths[i] = w[i];
    widths_pending = false;
  } else if (!same) {
    widths_pending = true;
  }
}

}  // namespace

const drone::Drone& logic() { return the_drone; }

void setup() {
  pinMode(pins::LASER, OUTPUT);
  digitalWrite(pins::LASER, LOW);
#ifdef DRONE_BENCH_PIN
  pinMode(DRONE_BENCH_PIN, OUTPUT);
#endif
  Serial.begin(drone::dp::BAUD);
  the_drone.begin(millis());
  widths_of(the_drone.outputs(), sent_widths);
  pulse_out::begin(sent_widths);
}

void loop() {
  const uint32_t now = millis();
#ifdef DRONE_BENCH_PIN
  // Bench builds mark the parsing work on a spare pin for the simulator.
  const bool busy = Serial.available() > 0;
  if (busy) digitalWrite(DRONE_BENCH_PIN, HIGH);
#endif
  // Bounded so timers and outputs are served even under a byte flood.
  for (uint8_t n = 0; n < 64 && Serial.available() > 0; ++n) {
    the_drone.receive(static_cast<uint8_t>(Serial.read()), now);
  }
  the_drone.update(now);
  apply_outputs();
#ifdef DRONE_BENCH_PIN
  if (busy) digitalWrite(DRONE_BENCH_PIN, LOW);
#endif
}

}  // namespace drone_app
