// USART0 driver for the AVR (see serial_link.h): two ring buffers and their interrupts.
#ifdef __AVR__

#include <DroneProtocol.h>
#include <avr/interrupt.h>
#include <avr/io.h>

#include "serial_link.h"

namespace {

// Head: where the next byte goes; tail: the next byte to take. One slot stays free, so head == tail is empty.
// The indexes are single bytes, so each side reads the other's atomically.
struct Ring {
  uint8_t data[serial_link::BUFFER];
  volatile uint8_t head;
  volatile uint8_t tail;
};
static_assert((serial_link::BUFFER & (serial_link::BUFFER - 1)) == 0, "the ring wraps by masking");
constexpr uint8_t MASK = serial_link::BUFFER - 1;

Ring rx;
Ring tx;

// Double speed (U2X), as the core sets it: 115200 baud is 117647 at 16 MHz (+2.1 %).
static_assert(F_CPU / 4 / drone_protocol::BAUD >= 1, "the baud rate is too high for this clock");
constexpr uint16_t UBRR_SETTING = static_cast<uint16_t>((F_CPU / 4 / drone_protocol::BAUD - 1) / 2);
static_assert(UBRR_SETTING < 4096, "the baud rate is too low for UBRR0");
// The rate the UART runs at must be near the spec's, or the Pi reads garbage: 4000000 baud ran at 2000000. 5 %
// lets 230400 through (222222, -3.5 %), which an Uno's USB bridge, clocked the same, makes the same way.
constexpr uint32_t ACTUAL_BAUD = F_CPU / 8 / (UBRR_SETTING + 1UL);
static_assert((ACTUAL_BAUD > drone_protocol::BAUD ? ACTUAL_BAUD - drone_protocol::BAUD
                                                  : drone_protocol::BAUD - ACTUAL_BAUD) * 100 <= 5 * drone_protocol::BAUD,
              "this clock cannot make the spec's baud rate within 5 %");

}  // namespace

#if defined(USART_RX_vect)
#define DRONE_USART_RX_VECT USART_RX_vect
#define DRONE_USART_UDRE_VECT USART_UDRE_vect
#else
#define DRONE_USART_RX_VECT USART0_RX_vect
#define DRONE_USART_UDRE_VECT USART0_UDRE_vect
#endif

// A byte arrived: kept, or dropped when the buffer is full (as HardwareSerial does).
ISR(DRONE_USART_RX_VECT) {
  const uint8_t byte = UDR0;
  const uint8_t head = rx.head;
  const uint8_t next = static_cast<uint8_t>((head + 1) & MASK);
  if (next != rx.tail) {
    rx.data[head] = byte;
    rx.head = next;
  }
}

// The transmitter is ready for another byte; with none left, this interrupt is switched off.
ISR(DRONE_USART_UDRE_VECT) {
  const uint8_t tail = tx.tail;
  if (tail == tx.head) {  // not reached: write() sets this interrupt after queuing
    UCSR0B &= static_cast<uint8_t>(~_BV(UDRIE0));
    return;
  }
  UDR0 = tx.data[tail];
  const uint8_t next = static_cast<uint8_t>((tail + 1) & MASK);
  tx.tail = next;
  if (next == tx.head) UCSR0B &= static_cast<uint8_t>(~_BV(UDRIE0));
}

namespace serial_link {

void begin() {
  UCSR0A = _BV(U2X0);
  UBRR0 = UBRR_SETTING;
  UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);  // 8 data bits, no parity, 1 stop bit
  UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
}

uint8_t available() { return static_cast<uint8_t>((rx.head - rx.tail) & MASK); }

uint8_t read() {
  const uint8_t tail = rx.tail;
  const uint8_t byte = rx.data[tail];
  rx.tail = static_cast<uint8_t>((tail + 1) & MASK);
  return byte;
}

bool write(const char* data, uint8_t length) {
  uint8_t head = tx.head;
  const uint8_t free = static_cast<uint8_t>((tx.tail - head - 1) & MASK);
  if (free < length) return false;
  for (uint8_t i = 0; i < length; ++i) {
    tx.data[head] = static_cast<uint8_t>(data[i]);
    head = static_cast<uint8_t>((head + 1) & MASK);
  }
  // The new head and the interrupt that sends it together: the interrupt, running between the two, could empty
  // the ring and switch itself off, and the store of the read UCSR0B would switch it on over an empty ring.
  const uint8_t sreg = SREG;
  cli();
  tx.head = head;
  UCSR0B |= _BV(UDRIE0);
  SREG = sreg;
  return true;
}

}  // namespace serial_link

#endif  // __AVR__
