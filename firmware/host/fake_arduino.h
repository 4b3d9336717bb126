// Test-side controls of the fake Arduino core.
#ifndef FAKE_ARDUINO_CONTROL_H
#define FAKE_ARDUINO_CONTROL_H

#include <stddef.h>
#include <stdint.h>

#include <string>

namespace fake {

// Same sizes as the AVR core's HardwareSerial, so overflow behaves alike.
constexpr size_t RX_BUFFER = 64;
constexpr size_t TX_BUFFER = 64;

void set_millis(uint32_t ms);
uint32_t now();
// Queues received bytes as the UART would; bytes beyond the buffer are lost
// (returns how many were taken).
size_t rx_push(const uint8_t* data, size_t length);
size_t rx_space();
// Takes up to `max` bytes the firmware wrote, as the UART would by sending
// them; the rest stay in the 64-byte buffer and keep it full.
std::string tx_take(size_t max = static_cast<size_t>(-1));
uint32_t serial_baud();
// Empties both serial buffers, as a board reset does.
void reset_serial();
int pin(uint8_t pin);

}  // namespace fake

#endif
