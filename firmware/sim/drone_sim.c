/*
 * simavr test bench for the drone firmware: runs the real .elf, injects UART
 * bytes at given simulated times, and reports what the pins and the UART did,
 * timed by the simulated cycle counter (deterministic, no wall clock).
 *
 *   drone_sim --elf FILE [--mcu atmega328p|atmega2560] --until MS [--script FILE]
 *
 * Script (file or stdin): one event per line, "<ms> <hex bytes>": the bytes
 * are queued for the UART at that simulated time and go in back to back at
 * the line's baud rate (the UART model paces them).
 *
 * Output, one JSON object per line (times in CPU cycles, 16 per microsecond):
 *   {"ev":"pulse","pin":P,"rise":C,"width":C}   a high pulse on Arduino pin P
 *   {"ev":"level","pin":P,"t":C,"v":0|1}         every level change (laser pin only)
 *   {"ev":"tx","t":C,"text":"..."}                a line the firmware sent
 *   {"ev":"end","t":C,"unsent":N,"asleep":S}      N = script bytes never taken, S = cycles the
 *                                                 CPU spent asleep (idle) in all
 *   {"ev":"load","t":C,"asleep":S}                with --load-every MS: the same count so far
 *
 * --profile FILE writes the cycles spent at each program address (awake).
 *
 * --paint ADDR fills the RAM from ADDR (the end of .bss, __heap_start) to
 * RAMEND with a pattern before the run, and reports at the end how far the
 * heap grew up and the stack grew down into it:
 *   {"ev":"ram","heap_start":A,"heap_top":A,"stack_low":A,"ramend":A}
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "avr_ioport.h"
#include "avr_uart.h"
#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_irq.h"

typedef struct {
  int pin;
  char port;
  int bit;
} pin_map_t;

/* Arduino pin -> AVR port bit, for the pins the firmware drives (7 is the
 * bench marker pin). */
static const pin_map_t uno_pins[] = {{2, 'D', 2}, {3, 'D', 3}, {4, 'D', 4}, {5, 'D', 5}, {6, 'D', 6},
                                     {7, 'D', 7}, {9, 'B', 1}, {10, 'B', 2}, {13, 'B', 5}};
static const pin_map_t mega_pins[] = {{2, 'E', 4}, {3, 'E', 5}, {4, 'G', 5}, {5, 'E', 3}, {6, 'H', 3},
                                      {7, 'H', 4}, {9, 'H', 6}, {10, 'B', 4}, {13, 'B', 7}};
#define PIN_COUNT 9
#define LASER_PIN 13

typedef struct {
  int pin;
  int level;
  int rose; /* a real rising edge was seen (the first event may be pinMode) */
  avr_cycle_count_t rise;
} watch_t;

typedef struct {
  avr_cycle_count_t when;
  uint8_t *bytes;
  size_t length;
} event_t;

static avr_t *avr;
static watch_t watches[PIN_COUNT];
static avr_irq_t *uart_in;
static int uart_xon;
static uint8_t *pending;
static size_t pending_head, pending_tail, pending_cap;
static event_t *events;
static size_t event_count, event_next;
static char tx_line[256];
static size_t tx_len;

static void no_sleep(avr_t *a, avr_cycle_count_t howLong) {
  (void)a;
  (void)howLong;
}

static void pin_changed(struct avr_irq_t *irq, uint32_t value, void *param) {
  (void)irq;
  watch_t *w = param;
  const int v = value ? 1 : 0;
  if (v == w->level) return;
  w->level = v;
  if (w->pin == LASER_PIN) printf("{\"ev\":\"level\",\"pin\":%d,\"t\":%llu,\"v\":%d}\n", w->pin, (unsigned long long)avr->cycle, v);
  if (v) {
    w->rise = avr->cycle;
    w->rose = 1;
  } else if (w->rose) {
    printf("{\"ev\":\"pulse\",\"pin\":%d,\"rise\":%llu,\"width\":%llu}\n", w->pin, (unsigned long long)w->rise,
           (unsigned long long)(avr->cycle - w->rise));
  }
}

static void flush_pending(void) {
  while (uart_xon && pending_head < pending_tail) avr_raise_irq(uart_in, pending[pending_head++]);
}

static void uart_xon_hook(struct avr_irq_t *irq, uint32_t value, void *param) {
  (void)irq;
  (void)value;
  (void)param;
  uart_xon = 1;
  flush_pending();
}

static void uart_xoff_hook(struct avr_irq_t *irq, uint32_t value, void *param) {
  (void)irq;
  (void)value;
  (void)param;
  uart_xon = 0;
}

static void uart_out_hook(struct avr_irq_t *irq, uint32_t value, void *param) {
  (void)irq;
  (void)param;
  if (tx_len < sizeof tx_line - 1) tx_line[tx_len++] = (char)value;
  if (value != '\n' && tx_len < sizeof tx_line - 1) return;
  printf("{\"ev\":\"tx\",\"t\":%llu,\"text\":\"", (unsigned long long)avr->cycle);
  for (size_t i = 0; i < tx_len; ++i) {
    const unsigned char c = (unsigned char)tx_line[i];
    if (c == '"' || c == '\\') printf("\\%c", c);
    else if (c == '\n') printf("\\n");
    else if (c < 0x20 || c >= 0x7f) printf("\\u%04x", c);
    else putchar(c);
  }
  printf("\"}\n");
  tx_len = 0;
}

static avr_cycle_count_t inject(struct avr_t *a, avr_cycle_count_t when, void *param) {
  (void)a;
  (void)when;
  (void)param;
  while (event_next < event_count && events[event_next].when <= avr->cycle) {
    const event_t *e = &events[event_next++];
    if (pending_tail + e->length > pending_cap) {
      pending_cap = (pending_tail + e->length) * 2;
      pending = realloc(pending, pending_cap);
    }
    memcpy(pending + pending_tail, e->bytes, e->length);
    pending_tail += e->length;
  }
  flush_pending();
  /* Re-arm for the next scripted event (0 = done). */
  return event_next < event_count ? events[event_next].when : 0;
}

static int by_time(const void *a, const void *b) {
  const event_t *x = a, *y = b;
  return x->when < y->when ? -1 : x->when > y->when;
}

static void read_script(FILE *f) {
  char *line = NULL;
  size_t line_cap = 0;
  size_t cap = 0;
  while (getline(&line, &line_cap, f) > 0) {
    char *p = line;
    while (*p == ' ') ++p;
    if (*p == '#' || *p == '\n' || *p == 0) continue;
    char *end;
    const double ms = strtod(p, &end);
    if (end == p) {
      fprintf(stderr, "bad script line: %s", line);
      exit(2);
    }
    p = end;
    while (*p == ' ') ++p;
    if (event_count == cap) {
      cap = cap ? cap * 2 : 64;
      events = realloc(events, cap * sizeof *events);
    }
    event_t *e = &events[event_count++];
    e->when = (avr_cycle_count_t)(ms * 16000.0 + 0.5);
    e->bytes = malloc(strlen(p) / 2 + 1);
    e->length = 0;
    while (p[0] && p[0] != '\n' && p[0] != '\r') {
      unsigned int v;
      if (sscanf(p, "%2x", &v) != 1 || !p[1]) {
        fprintf(stderr, "bad hex in script: %s", line);
        exit(2);
      }
      e->bytes[e->length++] = (uint8_t)v;
      p += 2;
    }
  }
  free(line);
  qsort(events, event_count, sizeof *events, by_time);
}

int main(int argc, char **argv) {
  const char *elf = NULL, *mcu = "atmega328p", *script = NULL;
  long paint = -1;
  double load_every_ms = 0;
  const char *profile = NULL;
  double until_ms = -1;
  for (int i = 1; i < argc; ++i) {
    if (!strcmp(argv[i], "--elf") && i + 1 < argc) elf = argv[++i];
    else if (!strcmp(argv[i], "--mcu") && i + 1 < argc) mcu = argv[++i];
    else if (!strcmp(argv[i], "--until") && i + 1 < argc) until_ms = atof(argv[++i]);
    else if (!strcmp(argv[i], "--script") && i + 1 < argc) script = argv[++i];
    else if (!strcmp(argv[i], "--paint") && i + 1 < argc) paint = strtol(argv[++i], NULL, 0);
    else if (!strcmp(argv[i], "--load-every") && i + 1 < argc) load_every_ms = atof(argv[++i]);
    else if (!strcmp(argv[i], "--profile") && i + 1 < argc) profile = argv[++i];
    else {
      fprintf(stderr, "usage: drone_sim --elf FILE [--mcu atmega328p|atmega2560] --until MS [--script FILE]\n");
      return 2;
    }
  }
  if (!elf || until_ms < 0) {
    fprintf(stderr, "--elf and --until are required\n");
    return 2;
  }
  FILE *sf = script ? fopen(script, "r") : stdin;
  if (!sf) {
    perror(script);
    return 2;
  }
  read_script(sf);

  static char outbuf[1 << 16];
  setvbuf(stdout, outbuf, _IOFBF, sizeof outbuf);

  elf_firmware_t fw;
  memset(&fw, 0, sizeof fw);
  if (elf_read_firmware(elf, &fw) != 0) {
    fprintf(stderr, "cannot read %s\n", elf);
    return 1;
  }
  avr = avr_make_mcu_by_name(mcu);
  if (!avr) {
    fprintf(stderr, "unknown mcu %s\n", mcu);
    return 1;
  }
  avr_init(avr);
  avr_load_firmware(avr, &fw);
  avr->frequency = 16000000; /* a plain ELF carries no clock */
  avr->sleep = no_sleep;     /* run flat out, never usleep() */

  uint32_t flags = 0;
  avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
  flags &= ~(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
  avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
  uart_in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
  avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), uart_out_hook, NULL);
  avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON), uart_xon_hook, NULL);
  avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF), uart_xoff_hook, NULL);

  const pin_map_t *map = strcmp(mcu, "atmega2560") == 0 ? mega_pins : uno_pins;
  for (int i = 0; i < PIN_COUNT; ++i) {
    watches[i].pin = map[i].pin;
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(map[i].port), map[i].bit), pin_changed,
                            &watches[i]);
  }
  const uint8_t PAINT = 0xA5;
  if (paint >= 0)
    for (long a = paint; a <= avr->ramend; ++a) avr->data[a] = PAINT;
  if (event_count) avr_cycle_timer_register(avr, events[0].when > avr->cycle ? events[0].when - avr->cycle : 1, inject, NULL);

  const avr_cycle_count_t end = (avr_cycle_count_t)(until_ms * 16000.0);
  int state = cpu_Running;
  avr_cycle_count_t asleep = 0;
  const avr_cycle_count_t load_step = (avr_cycle_count_t)(load_every_ms * 16000.0);
  avr_cycle_count_t next_load = load_step;
  /* --profile FILE: cycles spent at each program address while awake, written
   * as "address cycles" lines (byte addresses, for avr-addr2line / avr-nm). */
  uint64_t *pc_cycles = profile ? calloc(avr->flashend + 1, sizeof *pc_cycles) : NULL;
  while (avr->cycle < end && state != cpu_Done && state != cpu_Crashed) {
    const avr_cycle_count_t before = avr->cycle;
    const int was = avr->state;
    const avr_flashaddr_t pc = avr->pc;
    state = avr_run(avr);
    if (was == cpu_Sleeping) asleep += avr->cycle - before;
    else if (pc_cycles && pc <= avr->flashend) pc_cycles[pc] += avr->cycle - before;
    if (load_step && avr->cycle >= next_load) {
      printf("{\"ev\":\"load\",\"t\":%llu,\"asleep\":%llu}\n", (unsigned long long)avr->cycle,
             (unsigned long long)asleep);
      next_load += load_step;
    }
  }
  if (paint >= 0) {
    long heap_top = paint, stack_low = avr->ramend;
    while (heap_top <= avr->ramend && avr->data[heap_top] != PAINT) ++heap_top;
    /* The stack's deepest point: the lowest byte that is not paint, searching
     * down from the top through the untouched gap above the heap. */
    long a = heap_top;
    while (a <= avr->ramend && avr->data[a] == PAINT) ++a;
    stack_low = a;
    printf("{\"ev\":\"ram\",\"heap_start\":%ld,\"heap_top\":%ld,\"stack_low\":%ld,\"ramend\":%d}\n", paint, heap_top,
           stack_low, avr->ramend);
  }
  if (pc_cycles) {
    FILE *pf = fopen(profile, "w");
    if (!pf) {
      perror(profile);
      return 2;
    }
    for (uint32_t a = 0; a <= avr->flashend; ++a)
      if (pc_cycles[a]) fprintf(pf, "%u %llu\n", a, (unsigned long long)pc_cycles[a]);
    fclose(pf);
    free(pc_cycles);
  }
  size_t unsent = pending_tail - pending_head;
  for (size_t i = event_next; i < event_count; ++i) unsent += events[i].length;
  printf("{\"ev\":\"end\",\"t\":%llu,\"unsent\":%zu,\"state\":%d,\"asleep\":%llu}\n",
         (unsigned long long)avr->cycle, unsent, state, (unsigned long long)asleep);
  fflush(stdout);
  return state == cpu_Crashed ? 1 : 0;
}
