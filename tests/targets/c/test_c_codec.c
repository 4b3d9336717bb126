// The generated C99 codec against generated/vectors.json, its replies, and a seeded random byte stream against the
// plain reference model (reference.h). Usage: test_c_codec path/to/vectors.json; exits 1 naming the first failure.
#include <drone_protocol.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reference.h"

static int failures = 0;

#define CHECK(cond, ...)                                        \
  do {                                                          \
    if (!(cond)) {                                              \
      fprintf(stderr, "%s:%d: %s: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                             \
      fprintf(stderr, "\n");                                    \
      if (++failures > 20) exit(1);                             \
    }                                                           \
  } while (0)

/* Copies the text after `"key": ` on a vectors.json line (unquoted) into out; false if the key is absent. */
static bool field(const char *line, const char *key, char *out, size_t size) {
  char pattern[64];
  const char *at;
  size_t n = 0;
  snprintf(pattern, sizeof pattern, "\"%s\": ", key);
  at = strstr(line, pattern);
  if (at == NULL) return false;
  at += strlen(pattern);
  if (*at == '"') {
    for (++at; *at != '"' && *at != '\0' && n + 1 < size; ++at) out[n++] = *at;
  } else {
    for (; *at != ',' && *at != '}' && *at != '\0' && n + 1 < size; ++at) out[n++] = *at;
  }
  out[n] = '\0';
  return true;
}

static uint8_t valid[512][DP_WIRE_LENGTH];
static size_t valid_count = 0;

static void check_vector(const char *line) {
  char hex[64], ok[8], command[64], value[16], error[64];
  uint8_t frame[32];
  size_t n = 0, i;
  dp_command cmd;
  dp_error result;
  if (!field(line, "frame_hex", hex, sizeof hex) || !field(line, "ok", ok, sizeof ok)) return;
  for (i = 0; hex[i] != '\0' && hex[i + 1] != '\0'; i += 2) {
    unsigned byte;
    sscanf(hex + i, "%2x", &byte);
    frame[n++] = (uint8_t)byte;
  }
  result = dp_decode(frame, n, &cmd);
  if (strcmp(ok, "true") == 0) {
    uint8_t again[DP_WIRE_LENGTH];
    field(line, "command", command, sizeof command);
    field(line, "value", value, sizeof value);
    CHECK(result == DP_ERROR_NONE, "%s rejected: %s", hex, dp_error_name(result));
    if (result != DP_ERROR_NONE) return;
    CHECK(strcmp(dp_command_name(cmd.id), command) == 0 && cmd.value == atoi(value), "%s", hex);
    CHECK(dp_encode(cmd.id, cmd.value, again) == DP_ERROR_NONE && memcmp(again, frame, n) == 0, "%s", hex);
    if (valid_count < sizeof valid / sizeof valid[0]) memcpy(valid[valid_count++], frame, DP_WIRE_LENGTH);
#if DP_CHECK_LENGTH > 0
    frame[DP_WIRE_LENGTH - 1] = frame[DP_WIRE_LENGTH - 1] == '0' ? '1' : '0';
    CHECK(dp_decode(frame, n, &cmd) == DP_ERROR_BAD_CHECK, "%s with a wrong check", hex);
#endif
  } else {
    field(line, "error", error, sizeof error);
    CHECK(strcmp(dp_error_name(result), error) == 0, "%s: got %s, want %s", hex, dp_error_name(result), error);
#if DP_CHECK_LENGTH > 0
    if (result == DP_ERROR_OUT_OF_RANGE) { /* each check digit is compared before the range */
      frame[DP_WIRE_LENGTH - 1] = frame[DP_WIRE_LENGTH - 1] == '0' ? '1' : '0';
      CHECK(dp_decode(frame, n, &cmd) == DP_ERROR_BAD_CHECK, "%s out of range with a wrong check", hex);
    }
#endif
  }
}

static size_t ready_lines = 0;

/* One ready_lines entry of vectors.json: the line parses as the kind the spec's rule gives it. */
static void check_ready_line(const char *json) {
  char hex[512], kind[16], note[128], protocol[64], fingerprint[64], integrity[16];
  char line[256];
  size_t n = 0, i;
  dp_reply reply;
  dp_reply_status got;
  if (!field(json, "ready_hex", hex, sizeof hex) || !field(json, "kind", kind, sizeof kind)) return;
  field(json, "note", note, sizeof note);
  for (i = 0; hex[i] != '\0' && hex[i + 1] != '\0' && n < sizeof line; i += 2) {
    unsigned byte;
    sscanf(hex + i, "%2x", &byte);
    line[n++] = (char)byte;
  }
  got = dp_parse_reply(line, n, &reply);
  ++ready_lines;
  if (strcmp(kind, "ready") == 0) {
    field(json, "protocol", protocol, sizeof protocol);
    field(json, "fingerprint", fingerprint, sizeof fingerprint);
    field(json, "integrity", integrity, sizeof integrity);
    CHECK(got == DP_REPLY_OK && reply.kind == DP_REPLY_READY, "%s: refused", note);
    if (got != DP_REPLY_OK) return;
    CHECK(reply.protocol_length == strlen(protocol) && memcmp(reply.protocol, protocol, reply.protocol_length) == 0 &&
              reply.fingerprint_length == strlen(fingerprint) &&
              memcmp(reply.fingerprint, fingerprint, reply.fingerprint_length) == 0 &&
              reply.integrity_length == strlen(integrity) && memcmp(reply.integrity, integrity, reply.integrity_length) == 0,
          "%s: fields", note);
  } else if (strcmp(kind, "malformed") == 0) {
    CHECK(got == DP_REPLY_MALFORMED && reply.kind == DP_REPLY_READY, "%s: got %d", note, (int)got);
  } else if (strcmp(kind, "unknown") == 0) {
    CHECK(got == DP_REPLY_UNKNOWN, "%s: got %d", note, (int)got);
  } else {
    CHECK(strcmp(kind, "bad_check") == 0 && got == DP_REPLY_BAD_CHECK, "%s: %s, got %d", note, kind, (int)got);
  }
}

static void check_replies(void) {
  char line[DP_REPLY_MAX_LENGTH];
  dp_reply reply;
  size_t n = dp_write_ready(line);
  int i, s;
  CHECK(dp_parse_reply(line, n, &reply) == DP_REPLY_OK && reply.kind == DP_REPLY_READY, "ready");
  CHECK(reply.fingerprint_length == strlen(DP_SPEC_FINGERPRINT) &&
            memcmp(reply.fingerprint, DP_SPEC_FINGERPRINT, reply.fingerprint_length) == 0, "fingerprint");
  CHECK(reply.integrity_length == strlen(DP_INTEGRITY) && memcmp(reply.integrity, DP_INTEGRITY, reply.integrity_length) == 0,
        "integrity");
  for (s = 0; s < DP_STATE_COUNT; ++s) {
    dp_status status;
    status.state = dp_states[s];
    status.laser_on = s % 2 == 1;
    CHECK(dp_is_state((uint8_t)dp_states[s]) && strcmp(dp_state_name(dp_states[s]), "unknown") != 0, "state %d", s);
    for (i = 0; i < DP_COMMAND_COUNT; ++i) {
      const dp_command_info *info = dp_command_info_of((dp_command_id)i);
      dp_command cmd;
      cmd.id = (dp_command_id)i;
      cmd.category = info->category;
      cmd.direction = info->direction;
      cmd.value = info->min;
      n = dp_write_accepted(&cmd, status, line);
      CHECK(line[n - 1] == '\n' && n <= DP_REPLY_MAX_LENGTH, "%d", i);
      CHECK(dp_parse_reply(line, n, &reply) == DP_REPLY_OK && reply.kind == DP_REPLY_ACCEPTED && reply.command == cmd.id &&
                reply.status.state == status.state && reply.status.laser_on == status.laser_on, "%d", i);
    }
    for (i = 1; i <= DP_ERROR_COUNT; ++i) {
      n = dp_write_rejected((dp_error)i, status, line);
      CHECK(dp_parse_reply(line, n, &reply) == DP_REPLY_OK && reply.error == (dp_error)i && reply.status.state == status.state,
            "%d", i);
      CHECK(dp_error_from_code(dp_error_code((dp_error)i)) == (dp_error)i, "%d", i);
    }
    n = dp_write_failsafe(status, line);
    CHECK(dp_parse_reply(line, n, &reply) == DP_REPLY_OK && reply.kind == DP_REPLY_FAILSAFE &&
              reply.status.laser_on == status.laser_on, "failsafe");
  }
#if DP_CHECK_LENGTH > 0
  line[n - 2] = line[n - 2] == '0' ? '1' : '0';
  CHECK(dp_parse_reply(line, n, &reply) == DP_REPLY_BAD_CHECK, "a reply with a wrong check");
#else
  CHECK(dp_parse_reply("?", 1, &reply) == DP_REPLY_UNKNOWN, "unknown line");
  CHECK(dp_parse_reply(dp_reply_prefix(DP_REPLY_FAILSAFE), strlen(dp_reply_prefix(DP_REPLY_FAILSAFE)), &reply) ==
            DP_REPLY_MALFORMED, "a failsafe line without its status");
#endif
}

static uint64_t rng_state = 0x20261123u;
static uint32_t next(uint32_t n) {
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return (uint32_t)(rng_state % n);
}

static void check_stream(void) {
  dp_stream_parser parser = DP_STREAM_PARSER_INIT;
  reference ref;
  uint32_t now = 0;
  size_t fed = 0, frames = 0;
  int e;
  memset(&ref, 0, sizeof ref);
  while (fed < 200000) {
    uint8_t chunk[DP_WIRE_LENGTH + 2];
    uint32_t len, i;
    const uint32_t style = next(4);
    if (style <= 1) {
      memcpy(chunk, valid[next((uint32_t)valid_count)], DP_WIRE_LENGTH);
      len = DP_WIRE_LENGTH;
    } else if (style == 2) {
      len = next(8);
      for (i = 0; i < len; ++i) chunk[i] = (uint8_t)next(256);
    } else {
      memcpy(chunk, valid[next((uint32_t)valid_count)], DP_WIRE_LENGTH);
      len = next(DP_WIRE_LENGTH);
    }
    for (i = 0; i < len; ++i, ++fed) {
      dp_command cmd;
      bool got, want;
      if (next(50) == 0) now += 1 + next(3 * DP_INTER_BYTE_TIMEOUT_MS);
      got = dp_stream_feed(&parser, chunk[i], now, &cmd);
      want = reference_feed(&ref, chunk[i], now);
      CHECK(got == want, "byte %zu", fed);
      CHECK(dp_stream_pending(&parser) == ref.length, "byte %zu", fed);
      if (got && want) {
        uint8_t again[DP_WIRE_LENGTH];
        CHECK(dp_encode(cmd.id, cmd.value, again) == DP_ERROR_NONE && memcmp(again, ref.frame, DP_WIRE_LENGTH) == 0,
              "byte %zu", fed);
        ++frames;
      }
    }
  }
  for (e = 1; e <= DP_ERROR_COUNT; ++e) {
    const uint32_t want = ref.counts[e] > UINT16_MAX ? UINT16_MAX : ref.counts[e];
    CHECK(dp_stream_error_count(&parser, (dp_error)e) == want, "%s", dp_error_name((dp_error)e));
  }
  CHECK(frames > 10000 && dp_stream_error_count(&parser, DP_ERROR_TIMEOUT) > 100, "the stream exercises too little");
  dp_stream_init(&parser);
  CHECK(dp_stream_pending(&parser) == 0 && dp_stream_error_count(&parser, DP_ERROR_BAD_CATEGORY) == 0, "init");
}

int main(int argc, char **argv) {
  static char line[4096];
  size_t vectors = 0, headers = 0;
  FILE *file;
  if (argc != 2) {
    fprintf(stderr, "usage: %s vectors.json\n", argv[0]);
    return 2;
  }
  file = fopen(argv[1], "r");
  if (file == NULL) {
    perror(argv[1]);
    return 2;
  }
  while (fgets(line, sizeof line, file) != NULL) {
    char text[32];
    if (strstr(line, "\"fingerprint\"") != NULL && strstr(line, "\"ready_hex\"") == NULL) CHECK(strstr(line, DP_SPEC_SHA256) != NULL, "vectors of another spec");
    if (strstr(line, "\"frame_hex\"") == NULL && strstr(line, "\"ready_hex\"") == NULL &&
        field(line, "integrity", text, sizeof text)) {
      CHECK(strcmp(text, DP_INTEGRITY) == 0, "vectors of integrity mode %s", text);
      ++headers;
    }
    if (strstr(line, "\"frame_hex\"") == NULL && field(line, "wire_length", text, sizeof text)) {
      CHECK(atoi(text) == DP_WIRE_LENGTH, "vectors of %s-byte wire frames", text);
      ++headers;
    }
    if (strstr(line, "\"frame_hex\"") != NULL) {
      check_vector(line);
      ++vectors;
    }
    if (strstr(line, "\"ready_hex\"") != NULL) check_ready_line(line);
  }
  fclose(file);
  CHECK(vectors > 50 && valid_count > 20, "too few vectors (%zu)", vectors);
  CHECK(headers == 2, "vectors.json names its integrity mode and wire length");
  CHECK(ready_lines > 100, "too few ready lines (%zu)", ready_lines);
  check_replies();
  if (valid_count > 0) check_stream();
  if (failures == 0) printf("C codec: %zu vectors, replies and a 200000-byte stream agree\n", vectors);
  return failures == 0 ? 0 : 1;
}
