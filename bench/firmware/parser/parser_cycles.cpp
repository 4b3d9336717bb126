// Cycles per byte of the generated StreamParser on the ATmega328P, against a naive 6-byte atoi in the same
// binary. Plain avr-libc, no Arduino core. Each measured span raises Arduino pin 7 (PD7) and lowers it again;
// the simavr harness (firmware/sim/drone_sim.c) reports the span's width in cycles. Spans, in order:
//   8 empty spans (the cost of the marking itself), then per stream, N_PASSES times:
//   clean:   back-to-back valid frames of every command, fed byte by byte to StreamParser::feed()
//   garbage: pseudo-random bytes (xorshift), fed byte by byte
//   naive:   the clean stream read as 6-byte frames with a fixed atoi (no checks at all): the floor
//   empty:   the parser's loop (byte loads, the clock) with no parsing: subtracted to give the parser's own cost
// The streams are built in RAM before the marks, so the spans hold the parsing alone. The clock passed to feed()
// advances 1 ms every 12 bytes, as millis() does at 115200 baud back to back.
#include <avr/io.h>
#include <stdint.h>

#include <DroneProtocol.h>

namespace dp = drone_protocol;

constexpr uint16_t STREAM_BYTES = 96 * dp::WIRE_LENGTH;
constexpr uint8_t N_PASSES = 3;

static uint8_t stream[STREAM_BYTES];
volatile uint16_t sink;  // results go here, so nothing is optimised away

static inline void mark_on() { PORTD |= _BV(PD7); }
static inline void mark_off() { PORTD &= static_cast<uint8_t>(~_BV(PD7)); }

static void build_clean() {
  uint16_t n = 0;
  dp::CommandIndex id = 0;
  while (n + dp::WIRE_LENGTH <= STREAM_BYTES) {
    const dp::CommandId cid = static_cast<dp::CommandId>(id);
    const uint16_t lo = dp::command_min(cid), hi = dp::command_max(cid);
    const uint16_t value = static_cast<uint16_t>(lo + (static_cast<uint16_t>(n * 7u) % (hi - lo + 1u)));
    dp::encode(cid, value, &stream[n]);
    n = static_cast<uint16_t>(n + dp::WIRE_LENGTH);
    if (++id == dp::COMMAND_COUNT) id = 0;
  }
}

static void build_garbage() {
  uint16_t x = 0xACE1u;
  for (uint16_t i = 0; i < STREAM_BYTES; ++i) {
    x ^= static_cast<uint16_t>(x << 7);
    x ^= static_cast<uint16_t>(x >> 9);
    x ^= static_cast<uint16_t>(x << 8);
    stream[i] = static_cast<uint8_t>(x);
  }
}

__attribute__((noinline)) static void run_parser() {
  dp::StreamParser parser;
  uint32_t now = 1000;
  uint8_t tick = 0;
  uint16_t frames = 0;
  mark_on();
  for (uint16_t i = 0; i < STREAM_BYTES; ++i) {
    if (parser.feed(stream[i], now)) ++frames;
    if (++tick == 12) {
      tick = 0;
      ++now;
    }
  }
  mark_off();
  sink = frames;
}

// The byte loop and the clock of run_parser() without the parser: what the parser's span holds besides it.
__attribute__((noinline)) static void run_empty() {
  uint32_t now = 1000;
  uint8_t tick = 0;
  uint16_t sum = 0;
  mark_on();
  for (uint16_t i = 0; i < STREAM_BYTES; ++i) {
    sum = static_cast<uint16_t>(sum + (stream[i] ^ static_cast<uint8_t>(now)));
    if (++tick == 12) {
      tick = 0;
      ++now;
    }
  }
  mark_off();
  sink = sum;
}

__attribute__((noinline)) static void run_naive() {
  uint16_t sum = 0;
  mark_on();
  for (uint16_t i = 0; i + dp::FRAME_LENGTH <= STREAM_BYTES; i = static_cast<uint16_t>(i + dp::WIRE_LENGTH)) {
    const uint8_t* f = &stream[i];
    uint16_t value = 0;
    for (uint8_t k = 2; k < dp::FRAME_LENGTH; ++k) value = static_cast<uint16_t>(value * 10u + (f[k] - '0'));
    sum = static_cast<uint16_t>(sum + f[0] + f[1] + value);
  }
  mark_off();
  sink = sum;
}

int main() {
  DDRD |= _BV(PD7);
  for (uint8_t i = 0; i < 8; ++i) {
    mark_on();
    mark_off();
  }
  for (uint8_t p = 0; p < N_PASSES; ++p) {
    build_clean();
    run_parser();
    build_garbage();
    run_parser();
    build_clean();
    run_naive();
    run_empty();
  }
  for (;;) {
  }
}
