// Text output for the codec's AVR programs: the ATmega328P's UART (polled, no RAM) or, on the host, stdout.
#ifndef OUT_H
#define OUT_H

#include <stdint.h>

#ifdef __AVR__
#include <avr/io.h>
#include <avr/pgmspace.h>

static inline void out_init(void) {
  UBRR0 = 0; /* 1 Mbaud at 16 MHz: the simulator paces the bytes, nothing listens at a real rate */
  UCSR0B = _BV(TXEN0);
  UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
}

static inline void out_char(char c) {
  while (!(UCSR0A & _BV(UDRE0))) {
  }
  UDR0 = (uint8_t)c;
}

/* A string in flash, as the codec's _P functions return. */
static inline void out_flash(const char *text) {
  char c;
  while ((c = (char)pgm_read_byte(text++)) != '\0') out_char(c);
}
#else
#include <stdio.h>

static inline void out_init(void) {}
static inline void out_char(char c) { putchar(c); }
static inline void out_flash(const char *text) { fputs(text, stdout); }
#endif

static inline void out_bytes(const char *text, uint16_t length) {
  uint16_t i;
  for (i = 0; i < length; ++i) out_char(text[i]);
}

static inline void out_text(const char *text) {
  while (*text != '\0') out_char(*text++);
}

/* A space, then `value` in decimal. */
static inline void out_number(int32_t value) {
  char digits[11];
  uint8_t n = 0;
  uint32_t magnitude = value < 0 ? (uint32_t)-value : (uint32_t)value;
  out_char(' ');
  if (value < 0) out_char('-');
  do {
    digits[n++] = (char)('0' + magnitude % 10u);
    magnitude /= 10u;
  } while (magnitude != 0);
  while (n > 0) out_char(digits[--n]);
}

#endif
