// Pin output without the Arduino core's digitalWrite()/pinMode(), which carry
// PWM and pull-up handling this firmware never needs (about 250 bytes of
// flash on the Uno). The host build keeps the (fake) Arduino calls.
#ifndef DRONE_PIN_IO_H
#define DRONE_PIN_IO_H

#include <Arduino.h>
#include <stdint.h>

namespace pin_io {

// Makes `pin` an output, low. Before the pulse interrupt runs only: the
// read-modify-write of the port is not atomic.
inline void output_low(uint8_t pin) {
#ifdef __AVR__
  const uint8_t port = digitalPinToPort(pin);
  const uint8_t mask = digitalPinToBitMask(pin);
  *portOutputRegister(port) &= static_cast<uint8_t>(~mask);
  *portModeRegister(port) |= mask;
#else
  pinMode(pin, OUTPUT);
  digitalWrite(pin, LOW);
#endif
}

// Sets an output pin known to be at the other level. On the AVR one store to
// PINx toggles it: atomic, so safe beside the pulse interrupt toggling other
// pins of the same port.
inline void flip_to(uint8_t pin, bool high) {
#ifdef __AVR__
  (void)high;
  *portInputRegister(digitalPinToPort(pin)) = digitalPinToBitMask(pin);
#else
  digitalWrite(pin, high ? HIGH : LOW);
#endif
}

}  // namespace pin_io

#endif
