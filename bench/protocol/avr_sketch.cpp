// The smallest useful ATmega328P program, built twice by the bench with the same flags: without the protocol
// (every received byte is echoed to a register) and with -DWITH_PARSER (every byte goes through the generated
// StreamParser and valid frames through dispatch() to one handler per category). The difference in flash and
// RAM is what the parser costs. Plain avr-libc: UART polled at 115200 baud, Timer0 overflow for milliseconds.
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#ifdef WITH_PARSER
#include <DroneProtocol.h>
#endif

static volatile uint32_t g_millis;

ISR(TIMER0_OVF_vect) {
  // 16 MHz / 64 / 256 = 1.024 ms per overflow: close enough for a size benchmark, identical in both builds.
  g_millis = g_millis + 1;
}

static uint32_t millis_now() {
  const uint8_t sreg = SREG;
  cli();
  const uint32_t m = g_millis;
  SREG = sreg;
  return m;
}

static void uart_init() {
  UCSR0A = _BV(U2X0);
  UBRR0 = 16;  // 115200 baud at 16 MHz with U2X
  UCSR0B = _BV(RXEN0) | _BV(TXEN0);
  UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
}

static uint8_t uart_getc() {
  while (!(UCSR0A & _BV(RXC0))) {
  }
  return UDR0;
}

#ifdef WITH_PARSER
// One handler per category: each drives a different register, so the dispatch cannot fold away.
struct Handlers {
  void on_move(const drone_protocol::Command& c) { OCR1A = c.value; }
  void on_turn(const drone_protocol::Command& c) { OCR1B = c.value; }
  void on_servo(const drone_protocol::Command& c) { OCR2A = static_cast<uint8_t>(c.value); }
  void on_laser(const drone_protocol::Command&) { PORTB ^= _BV(PB5); }
  void on_init(const drone_protocol::Command& c) { GPIOR1 = c.direction; }
};
static drone_protocol::StreamParser parser;
static Handlers handlers;
#endif

int main() {
  TCCR0B = _BV(CS01) | _BV(CS00);
  TIMSK0 = _BV(TOIE0);
  DDRB = _BV(PB5);
  uart_init();
  sei();
  for (;;) {
    const uint8_t byte = uart_getc();
    const uint32_t now = millis_now();
#ifdef WITH_PARSER
    if (parser.feed(byte, now)) drone_protocol::dispatch(parser.command(), handlers);
#else
    GPIOR0 = byte;
    GPIOR2 = static_cast<uint8_t>(now);
#endif
  }
}
