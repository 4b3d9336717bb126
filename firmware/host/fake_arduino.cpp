#include "fake_arduino.h"

#include <deque>

#include "Arduino.h"

namespace {
uint32_t g_millis = 0;
uint32_t g_baud = 0;
std::deque<uint8_t> g_rx;
std::string g_tx;
int g_pins[64] = {};
}  // namespace

FakeSerial Serial;

uint32_t millis() { return g_millis; }
void pinMode(uint8_t, uint8_t) {}
void digitalWrite(uint8_t pin, uint8_t value) {
  if (pin < 64) g_pins[pin] = value ? HIGH : LOW;
}
int digitalRead(uint8_t pin) { return pin < 64 ? g_pins[pin] : LOW; }

void FakeSerial::begin(unsigned long baud) { g_baud = static_cast<uint32_t>(baud); }
int FakeSerial::available() { return static_cast<int>(g_rx.size()); }
int FakeSerial::read() {
  if (g_rx.empty()) return -1;
  const uint8_t b = g_rx.front();
  g_rx.pop_front();
  return b;
}
// The AVR core reports one byte less than its buffer size.
int FakeSerial::availableForWrite() { return static_cast<int>(fake::TX_BUFFER - 1 - g_tx.size()); }
size_t FakeSerial::write(uint8_t byte) { return write(&byte, 1); }
size_t FakeSerial::write(const uint8_t* data, size_t length) {
  g_tx.append(reinterpret_cast<const char*>(data), length);
  return length;
}

namespace fake {

void set_millis(uint32_t ms) { g_millis = ms; }
uint32_t now() { return g_millis; }
size_t rx_space() { return RX_BUFFER - 1 - g_rx.size(); }
size_t rx_push(const uint8_t* data, size_t length) {
  size_t taken = 0;
  while (taken < length && rx_space() > 0) g_rx.push_back(data[taken++]);
  return taken;
}
std::string tx_take(size_t max) {
  std::string out = g_tx.substr(0, max);
  g_tx.erase(0, out.size());
  return out;
}
uint32_t serial_baud() { return g_baud; }
void reset_serial() {
  g_rx.clear();
  g_tx.clear();
}
int pin(uint8_t p) { return digitalRead(p); }

}  // namespace fake
