// Baseline for the firmware benchmark: the same 6-byte frames parsed the way
// typical Arduino sketches do it (Serial.readString, String.substring,
// toInt), driving the same pulse generator and answering like our firmware
// ("A<category><direction>\n"), with no safety logic at all. Hand-written
// constants are the point here: this is the code the generated parser replaces.
#include "pins.h"
#include "pulse_out.h"

namespace {

// Arduino's default readString timeout is 1000 ms, which glues together every
// frame of a 50 Hz stream; typical sketches lower it. 5 ms spans a frame.
const unsigned long READ_TIMEOUT_MS = 5;

uint16_t widths[pulse::OUTPUTS] = {1500, 1500, 1029, 1524, 1165, 1472, 1472};
bool dirty = false;
bool laser = false;
int pan = 90, tilt = 90;

uint16_t servo_us(int deg) { return 544 + (deg * (2400L - 544) + 90) / 180; }

// Bench builds toggle a spare pin around the work the simulator times:
// DRONE_BENCH_PIN marks all the handling of received bytes, and
// DRONE_BENCH_PARSER_PIN only the parsing (readString .. toInt).
#if defined(DRONE_BENCH_PIN)
#define MARK_PIN DRONE_BENCH_PIN
#elif defined(DRONE_BENCH_PARSER_PIN)
#define MARK_PIN DRONE_BENCH_PARSER_PIN
#endif
#ifdef MARK_PIN
volatile uint8_t* mark_reg;
uint8_t mark_mask;
void bench_mark() { *mark_reg = mark_mask; }
#endif

}  // namespace

void setup() {
  Serial.begin(115200);
  Serial.setTimeout(READ_TIMEOUT_MS);
  pinMode(pins::LASER, OUTPUT);
#ifdef MARK_PIN
  pinMode(MARK_PIN, OUTPUT);
  mark_reg = portInputRegister(digitalPinToPort(MARK_PIN));
  mark_mask = digitalPinToBitMask(MARK_PIN);
  for (uint8_t i = 0; i < 8; ++i) {  // calibration: empty marked spans
    bench_mark();
    bench_mark();
  }
#endif
  pulse_out::begin(widths);
}

void loop() {
  if (Serial.available() > 0) {
#ifdef DRONE_BENCH_PIN
    bench_mark();
#endif
#ifdef DRONE_BENCH_PARSER_PIN
    bench_mark();
#endif
    String msg = Serial.readString();
    const bool complete = msg.length() == 6;
    char c = 0, d = 0;
    int value = 0;
    if (complete) {
      c = msg.charAt(0);
      d = msg.charAt(1);
      value = msg.substring(2, 6).toInt();
    }
#ifdef DRONE_BENCH_PARSER_PIN
    bench_mark();
#endif
    if (complete) {
      bool ok = true;
      if (c == 'm') {
        if (d == 'f' || d == 'b') widths[pulse::PITCH] = value;
        else if (d == 'l' || d == 'r') widths[pulse::ROLL] = value;
        else if (d == 'u' || d == 'd') widths[pulse::THROTTLE] = value;
        else ok = false;
      } else if (c == 't') {
        if (d == 'l' || d == 'r') widths[pulse::YAW] = value;
        else ok = false;
      } else if (c == 's') {
        if (d == 'u') tilt = constrain(tilt + value, 0, 180);
        else if (d == 'd') tilt = constrain(tilt - value, 0, 180);
        else if (d == 'l') pan = constrain(pan - value, 0, 180);
        else if (d == 'r') pan = constrain(pan + value, 0, 180);
        else if (d == 'x') pan = tilt = 90;
        else ok = false;
        widths[pulse::PAN] = servo_us(pan);
        widths[pulse::TILT] = servo_us(tilt);
      } else if (c == 'l') {
        laser = !laser;
        digitalWrite(pins::LASER, laser ? HIGH : LOW);
      } else {
        ok = false;
      }
      if (ok) {
        dirty = true;
        Serial.print('A');
        Serial.print(c);
        Serial.print(d);
        Serial.print('\n');
      }
    }
#ifdef DRONE_BENCH_PIN
    bench_mark();
#endif
  }
  if (dirty && pulse_out::update(widths)) dirty = false;
}
