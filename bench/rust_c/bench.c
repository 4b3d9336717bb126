// C99 codec benchmark: encode and decode per frame and the stream parser per byte, each against a hand-written
// floor in the same run. Usage: bench <stream file> time | stream (stream: only the parser, for callgrind).
#define _POSIX_C_SOURCE 199309L
#include <drone_protocol.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static uint8_t cats[DP_COMMAND_COUNT], dirs[DP_COMMAND_COUNT];
static uint16_t mins[DP_COMMAND_COUNT], maxs[DP_COMMAND_COUNT];
static volatile size_t sink;

/* Floor decode: slice and parse, a linear scan of the table; no error kinds. */
static int floor_decode(const uint8_t *f, uint16_t *value) {
  uint16_t v = 0;
  int i;
  for (i = 2; i < DP_FRAME_LENGTH; ++i) {
    if (f[i] < '0' || f[i] > '9') return -1;
    v = (uint16_t)(v * 10 + (f[i] - '0'));
  }
  for (i = 0; i < DP_COMMAND_COUNT; ++i) {
    if (cats[i] == f[0] && dirs[i] == f[1]) break;
  }
  if (i == DP_COMMAND_COUNT || v < mins[i] || v > maxs[i]) return -1;
  *value = v;
  return i;
}

/* Floor encode: a template (category, direction, zero-padded digits); no range check. */
static void floor_encode(int i, uint16_t value, uint8_t *out) {
  int k;
  out[0] = cats[i];
  out[1] = dirs[i];
  for (k = DP_FRAME_LENGTH - 1; k >= 2; --k) {
    out[k] = (uint8_t)('0' + value % 10);
    value /= 10;
  }
}

size_t bench_stream(const uint8_t *bytes, size_t len);
size_t bench_stream(const uint8_t *bytes, size_t len) {
  dp_stream_parser parser = DP_STREAM_PARSER_INIT;
  dp_command cmd;
  size_t found = 0, i;
  for (i = 0; i < len; ++i) found += dp_stream_feed(&parser, bytes[i], 0, &cmd);
  return found;
}

static size_t floor_stream(const uint8_t *bytes, size_t len) {
  uint8_t buf[DP_FRAME_LENGTH];
  size_t n = 0, found = 0, i;
  uint16_t v;
  for (i = 0; i < len; ++i) {
    buf[n++] = bytes[i];
    if (n == DP_FRAME_LENGTH) {
      if (floor_decode(buf, &v) >= 0) {
        ++found;
        n = 0;
      } else {
        memmove(buf, buf + 1, --n);
      }
    }
  }
  return found;
}

static double now_ns(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e9 + ts.tv_nsec;
}

#define BEST(result, count, body)                       \
  do {                                                  \
    int rep;                                            \
    result = 1e30;                                      \
    for (rep = 0; rep < 15; ++rep) {                    \
      const double start = now_ns();                    \
      body;                                             \
      const double t = (now_ns() - start) / (count);    \
      if (t < result) result = t;                       \
    }                                                   \
  } while (0)

int main(int argc, char **argv) {
  static uint8_t stream[1 << 24];
  static uint8_t frames[100000][DP_FRAME_LENGTH];
  static int ids[100000];
  static uint16_t values[100000];
  size_t len, n = 0, i;
  uint8_t out[DP_WIRE_LENGTH];
  double enc, enc_floor, dec, dec_floor, st, st_floor;
  FILE *f = fopen(argv[1], "rb");
  if (argc != 3 || f == NULL) return 2;
  len = fread(stream, 1, sizeof stream, f);
  fclose(f);
  if (strcmp(argv[2], "stream") == 0) {
    printf("%zu\n", bench_stream(stream, len));
    return 0;
  }
  for (i = 0; i < DP_COMMAND_COUNT; ++i) {
    const dp_command_info *info = dp_command_info_of((dp_command_id)i);
    cats[i] = info->category, dirs[i] = info->direction, mins[i] = info->min, maxs[i] = info->max;
  }
  for (i = 0; i + DP_FRAME_LENGTH <= len && n < 100000; i += DP_FRAME_LENGTH) {
    dp_command c;
    if (dp_decode(stream + i, DP_FRAME_LENGTH, &c) == DP_ERROR_NONE) {
      memcpy(frames[n], stream + i, DP_FRAME_LENGTH);
      ids[n] = c.id, values[n] = c.value;
      ++n;
    }
  }
  BEST(enc, n, for (i = 0; i < n; ++i) { dp_encode((dp_command_id)ids[i], values[i], out); sink += out[5]; });
  BEST(enc_floor, n, for (i = 0; i < n; ++i) { floor_encode(ids[i], values[i], out); sink += out[5]; });
  BEST(dec, n, for (i = 0; i < n; ++i) { dp_command c; if (dp_decode(frames[i], DP_FRAME_LENGTH, &c) == 0) sink += c.value; });
  BEST(dec_floor, n, for (i = 0; i < n; ++i) { uint16_t v; if (floor_decode(frames[i], &v) >= 0) sink += v; });
  BEST(st, len, sink += bench_stream(stream, len));
  BEST(st_floor, len, sink += floor_stream(stream, len));
  printf("encode_ns %.2f %.2f\ndecode_ns %.2f %.2f\nstream_ns_per_byte %.2f %.2f\n", enc, enc_floor, dec, dec_floor, st,
         st_floor);
  return 0;
}
