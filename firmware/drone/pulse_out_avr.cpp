// Timer1 pulse generator for the AVR. The hardware PWM modes are not used:
// our pins are not all Timer1 pins, and simavr mis-models mode 14, while this
// compare-interrupt scheme simulates exactly.
#ifdef __AVR__

#include <Arduino.h>
#include <avr/interrupt.h>
#include <avr/pgmspace.h>

#include "pins.h"
#include "pin_io.h"
#include "pulse_out.h"

namespace {

const uint8_t kPins[pulse::LINE_COUNT] PROGMEM = {pins::ROLL, pins::PITCH, pins::THROTTLE, pins::YAW,
                                          pins::MODE, pins::PAN,   pins::TILT,     pins::PPM};
// Edges are made by writing the bit mask to the pin's PINx register, which
// toggles it in one store: no read-modify-write, so the lowering and the
// raising in one interrupt happen two cycles apart whatever the slot, and
// every pulse gets the same latency at both ends. Entry NO_LINE has mask 0.
volatile uint8_t* toggle_reg[pulse::LINE_COUNT + 1];
uint8_t toggle_mask[pulse::LINE_COUNT + 1];

// Double buffer: the loop fills the idle schedule and sets `swap_pending`;
// the interrupt adopts it at the frame boundary and clears the flag. Each
// side only touches shared data while the flag says it owns it, so no
// interrupt ever has to be disabled (which would add pulse jitter).
pulse::Schedule schedules[2];
volatile uint8_t active = 0;
volatile bool swap_pending = false;
uint8_t slot_index = 0;

void build(const uint16_t width_us[pulse::OUTPUTS], pulse::Schedule& s) {
#ifdef DRONE_PPM
  pulse::build_ppm(width_us, s);
#else
  pulse::build_parallel(width_us, s);
#endif
}

}  // namespace

// The compare match fires EARLY_TICKS before each edge, and the interrupt
// spins on TCNT1 until the edge's exact tick. Other interrupts (the UART's,
// millis') that delay our entry are thus absorbed as long as they are shorter
// than the lead, instead of showing up as pulse jitter. Cost: about 1 % CPU.
// (DRONE_PULSE_LEAD_US=0 builds the plain scheme, for the jitter benchmark.)
#ifndef DRONE_PULSE_LEAD_US
#define DRONE_PULSE_LEAD_US 40
#endif
constexpr uint16_t EARLY_TICKS = DRONE_PULSE_LEAD_US * pulse::TICKS_PER_US;
static_assert(EARLY_TICKS < 500 * pulse::TICKS_PER_US, "the lead must stay shorter than the shortest slot");
uint16_t edge_at;  // TCNT1 value of the next edge

ISR(TIMER1_COMPA_vect) {
  const pulse::Schedule& sched = schedules[active];
  const pulse::Slot& s = sched.slot[slot_index];
  volatile uint8_t* const lower_reg = toggle_reg[s.lower];
  const uint8_t lower_mask = toggle_mask[s.lower];
  volatile uint8_t* const raise_reg = toggle_reg[s.raise];
  const uint8_t raise_mask = toggle_mask[s.raise];
  const uint16_t at = edge_at;
  while (static_cast<int16_t>(TCNT1 - at) < 0) {
  }
  *lower_reg = lower_mask;
  *raise_reg = raise_mask;
  // Relative to the previous edge, not to now: latency never accumulates.
  edge_at = at + s.ticks;
  OCR1A = edge_at - EARLY_TICKS;
  if (++slot_index >= sched.count) {
    slot_index = 0;
    if (swap_pending) {
      active ^= 1;
      swap_pending = false;
    }
  }
}

namespace pulse_out {

void begin(const uint16_t width_us[pulse::OUTPUTS]) {
  for (uint8_t i = 0; i < pulse::LINE_COUNT; ++i) {
    const uint8_t pin = pgm_read_byte(&kPins[i]);
    pin_io::output_low(pin);
    toggle_reg[i] = portInputRegister(digitalPinToPort(pin));
    toggle_mask[i] = digitalPinToBitMask(pin);
  }
  toggle_reg[pulse::NO_LINE] = toggle_reg[0];
  toggle_mask[pulse::NO_LINE] = 0;  // writing 0 to PINx toggles nothing
  build(width_us, schedules[0]);
  active = 0;
  swap_pending = false;
  slot_index = 0;
  const uint8_t sreg = SREG;
  cli();
  // The core's init() left Timer1 in 8-bit phase-correct PWM at clk/64.
  TCCR1A = 0;
  TCCR1B = _BV(CS11);  // normal mode, clk/8
  edge_at = TCNT1 + 200;
  OCR1A = edge_at - EARLY_TICKS;
  TIFR1 = _BV(OCF1A);
  TIMSK1 |= _BV(OCIE1A);
  SREG = sreg;
}

bool update(const uint16_t width_us[pulse::OUTPUTS]) {
  if (swap_pending) return false;
  build(width_us, schedules[active ^ 1]);
  // Compiler barrier: the schedule must be in memory before the flag.
  __asm__ __volatile__("" ::: "memory");
  swap_pending = true;
  return true;
}

}  // namespace pulse_out

#endif  // __AVR__
