// libFuzzer target for the generated C99 codec (built with clang -fsanitize=fuzzer,address,undefined).
//
// Input: a byte stream fed to a dp_stream_parser one byte at a time; 0xFF n advances the clock by n ms (0xFF 0xFF
// feeds 0xFF itself). The same input drives dp_decode() on every 6-byte window and on the whole input, dp_encode()
// on (command, value) triples read from it, and dp_parse_reply() on it as a line.
// Invariants (a failure aborts): the parser agrees after every byte with the plain reference model (same frames,
// same pending bytes, same error counts); every command found or decoded lies in its range and re-encodes to the
// same bytes; dp_encode() succeeds exactly for values in range; names and codes are total.
#include <drone_protocol.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reference.h"

#define CHECK(cond)                                                                  \
  do {                                                                               \
    if (!(cond)) {                                                                   \
      fprintf(stderr, "invariant failed at %s:%d: %s\n", __FILE__, __LINE__, #cond); \
      abort();                                                                       \
    }                                                                                \
  } while (0)

static void check_command(const dp_command *cmd, const uint8_t *bytes) {
  const dp_command_info *info = dp_command_info_of(cmd->id);
  uint8_t again[DP_WIRE_LENGTH];
  CHECK(info != NULL && info->category == cmd->category && info->direction == cmd->direction);
  CHECK(cmd->value >= info->min && cmd->value <= info->max);
  CHECK(dp_encode(cmd->id, cmd->value, again) == DP_ERROR_NONE && memcmp(again, bytes, DP_WIRE_LENGTH) == 0);
}

static void fuzz_stream(const uint8_t *data, size_t size) {
  dp_stream_parser parser = DP_STREAM_PARSER_INIT;
  reference ref;
  uint32_t now = 0;
  size_t i;
  int e;
  memset(&ref, 0, sizeof ref);
  for (i = 0; i < size; ++i) {
    uint8_t byte = data[i];
    dp_command cmd;
    bool got;
    if (byte == 0xFF && i + 1 < size) {
      ++i;
      if (data[i] != 0xFF) {
        now += data[i];
        continue;
      }
    }
    got = dp_stream_feed(&parser, byte, now, &cmd);
    CHECK(got == reference_feed(&ref, byte, now));
    CHECK(dp_stream_pending(&parser) == ref.length && ref.length < DP_WIRE_LENGTH);
    if (got) check_command(&cmd, ref.frame);
    for (e = 1; e <= DP_ERROR_COUNT; ++e) {
      const uint32_t want = ref.counts[e] > UINT16_MAX ? UINT16_MAX : ref.counts[e];
      CHECK(dp_stream_error_count(&parser, (dp_error)e) == want);
    }
  }
}

static void fuzz_decode(const uint8_t *data, size_t size) {
  dp_command cmd;
  size_t at;
  const dp_error whole = dp_decode(data, size, &cmd);
  if (size < DP_WIRE_LENGTH) CHECK(whole == DP_ERROR_TOO_SHORT);
  if (size > DP_WIRE_LENGTH) CHECK(whole == DP_ERROR_TOO_LONG);
  for (at = 0; at + DP_WIRE_LENGTH <= size && at < 64; ++at) {
    const dp_error error = dp_decode(data + at, DP_WIRE_LENGTH, &cmd);
    CHECK(error == reference_first_error(data + at, DP_WIRE_LENGTH));
    if (error == DP_ERROR_NONE) check_command(&cmd, data + at);
  }
}

static void fuzz_encode(const uint8_t *data, size_t size) {
  size_t at;
  uint8_t frame[DP_WIRE_LENGTH];
  for (at = 0; at + 3 <= size && at < 48; at += 3) {
    const dp_command_id id = (dp_command_id)(data[at] % DP_COMMAND_COUNT);
    const uint16_t value = (uint16_t)(data[at + 1] << 8 | data[at + 2]);
    const dp_command_info *info = dp_command_info_of(id);
    const dp_error error = dp_encode(id, value, frame);
    dp_command cmd;
    CHECK((error == DP_ERROR_NONE) == (value >= info->min && value <= info->max));
    if (error != DP_ERROR_NONE) continue;
    CHECK(dp_decode(frame, DP_WIRE_LENGTH, &cmd) == DP_ERROR_NONE && cmd.id == id && cmd.value == value);
  }
  CHECK(dp_encode((dp_command_id)DP_COMMAND_COUNT, 0, frame) != DP_ERROR_NONE);
}

static void fuzz_names_and_replies(const uint8_t *data, size_t size) {
  char line[DP_REPLY_MAX_LENGTH];
  dp_reply reply;
  size_t n;
  if (size == 0) return;
  CHECK(dp_error_name((dp_error)data[0]) != NULL && dp_command_name((dp_command_id)data[0]) != NULL);
  CHECK(dp_error_code((dp_error)data[0]) > 0x20);
  {
    dp_status status;
    status.state = dp_states[data[0] % DP_STATE_COUNT];
    status.laser_on = (data[0] & 1) != 0;
    n = dp_write_rejected((dp_error)(data[0] % (DP_ERROR_COUNT + 1)), status, line);
  }
  CHECK(n >= 2 && n <= DP_REPLY_MAX_LENGTH && line[n - 1] == '\n');
  if (dp_parse_reply((const char *)data, size, &reply) == DP_REPLY_OK && reply.kind == DP_REPLY_READY) {
    CHECK(reply.protocol >= (const char *)data && reply.fingerprint + reply.fingerprint_length <= (const char *)data + size);
  }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  fuzz_stream(data, size);
  fuzz_decode(data, size);
  fuzz_encode(data, size);
  fuzz_names_and_replies(data, size);
  return 0;
}
