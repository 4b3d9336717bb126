// The serial link to the Pi, never blocking: received bytes in, whole reply lines out or not at all.
// On the AVR its own USART0 driver (serial_avr.cpp) instead of the core's HardwareSerial, whose Print and
// Stream virtuals (print(), peek(), flush(), ...) the firmware never calls but links anyway: about 700 bytes
// of flash. The host build goes through the fake core's Serial.
#ifndef DRONE_SERIAL_LINK_H
#define DRONE_SERIAL_LINK_H

#include <DroneProtocol.h>
#include <stdint.h>

#ifndef __AVR__
#include <Arduino.h>
#endif

namespace serial_link {

// Same sizes as the core's HardwareSerial (and the host's fake): 63 bytes each way.
constexpr uint8_t BUFFER = 64;

#ifdef __AVR__
void begin();                                // 8N1 at the spec's baud rate, receiver interrupt on
uint8_t available();                         // received bytes not read yet
uint8_t read();                              // the oldest of them (available() > 0)
bool write(const char* data, uint8_t length);  // queues all of `data`, or nothing if it does not fit
#else
inline void begin() { Serial.begin(drone_protocol::BAUD); }
inline uint8_t available() { return static_cast<uint8_t>(Serial.available()); }
inline uint8_t read() { return static_cast<uint8_t>(Serial.read()); }
inline bool write(const char* data, uint8_t length) {
  if (Serial.availableForWrite() < static_cast<int>(length)) return false;
  Serial.write(reinterpret_cast<const uint8_t*>(data), length);
  return true;
}
#endif

}  // namespace serial_link

#endif
