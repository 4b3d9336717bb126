// Walks the pulse schedules the way the Timer1 interrupt does, for widths
// given on the command line, and prints what each line would carry as JSON:
// {"mode":..,"frame_us":..,"lines":[{"line":i,"highs":[us..],"rises":[us..],"period_us":..}..]}
// (highs: pulse lengths in the first frame; rises: rising-edge times in it)
// pytest (tests/firmware/test_pulse_schedule.py) checks it against the input.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pulse_schedule.h"

int main(int argc, char** argv) {
  if (argc != 2 + pulse::OUTPUTS || (strcmp(argv[1], "parallel") != 0 && strcmp(argv[1], "ppm") != 0)) {
    fprintf(stderr, "usage: pulse_schedule_test parallel|ppm W0..W6\n");
    return 2;
  }
  uint16_t w[pulse::OUTPUTS];
  for (int i = 0; i < pulse::OUTPUTS; ++i) w[i] = static_cast<uint16_t>(atoi(argv[2 + i]));
  pulse::Schedule s;
  const bool ppm = strcmp(argv[1], "ppm") == 0;
  if (ppm) {
    pulse::build_ppm(w, s);
  } else {
    pulse::build_parallel(w, s);
  }
  // Level and last rising edge per line, over two frames (in ticks).
  bool high[pulse::LINE_COUNT] = {};
  uint32_t rose[pulse::LINE_COUNT] = {};
  uint32_t first_rise[pulse::LINE_COUNT];
  uint32_t second_rise[pulse::LINE_COUNT];
  for (int i = 0; i < pulse::LINE_COUNT; ++i) first_rise[i] = second_rise[i] = 0xFFFFFFFFu;
  char highs[pulse::LINE_COUNT][512] = {};
  char rises[pulse::LINE_COUNT][512] = {};
  uint32_t t = 0, frame_ticks = 0;
  for (int frame = 0; frame < 2; ++frame) {
    for (uint8_t k = 0; k < s.count; ++k) {
      const pulse::Slot& sl = s.slot[k];
      if (sl.lower != pulse::NO_LINE) {
        if (!high[sl.lower]) {
          fprintf(stderr, "slot %u lowers line %u which is low\n", k, sl.lower);
          return 1;
        }
        high[sl.lower] = false;
        if (frame == 0) {
          char buf[16];
          snprintf(buf, sizeof buf, "%s%u", highs[sl.lower][0] ? "," : "", (t - rose[sl.lower]) / pulse::TICKS_PER_US);
          strcat(highs[sl.lower], buf);
        }
      }
      if (sl.raise != pulse::NO_LINE) {
        if (high[sl.raise]) {
          fprintf(stderr, "slot %u raises line %u which is high\n", k, sl.raise);
          return 1;
        }
        high[sl.raise] = true;
        rose[sl.raise] = t;
        if (frame == 0) {
          char buf[16];
          snprintf(buf, sizeof buf, "%s%u", rises[sl.raise][0] ? "," : "", t / pulse::TICKS_PER_US);
          strcat(rises[sl.raise], buf);
        }
        if (first_rise[sl.raise] == 0xFFFFFFFFu) first_rise[sl.raise] = t;
        else if (frame == 1 && second_rise[sl.raise] == 0xFFFFFFFFu) second_rise[sl.raise] = t;
      }
      t += sl.ticks;
    }
    if (frame == 0) frame_ticks = t;
  }
  printf("{\"mode\":\"%s\",\"slots\":%u,\"frame_us\":%u,\"lines\":[", ppm ? "ppm" : "parallel", s.count,
         frame_ticks / pulse::TICKS_PER_US);
  for (int i = 0; i < pulse::LINE_COUNT; ++i) {
    const long period = first_rise[i] == 0xFFFFFFFFu || second_rise[i] == 0xFFFFFFFFu
                            ? -1
                            : static_cast<long>((second_rise[i] - first_rise[i]) / pulse::TICKS_PER_US);
    printf("%s{\"line\":%d,\"highs\":[%s],\"rises\":[%s],\"period_us\":%ld}", i ? "," : "", i, highs[i], rises[i],
           period);
  }
  printf("]}\n");
  return 0;
}
