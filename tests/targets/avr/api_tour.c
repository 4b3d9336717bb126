// Prints what the C99 codec says of every command, error, state and reply, and what its stream parser finds in a
// stream of every command's frame: one line per item. On AVR the names come from the _P functions (flash) and the
// plain ones (inline, RAM); tests/targets/test_targets_c_avr.py runs it in simavr and compares its output with the
// host build's, whose codec the C tests check against the vectors.
#include "drone_protocol.h"
#include "out.h"

#ifdef __AVR__
#define FLASH_NAME(f) f##_P
#else
#define FLASH_NAME(f) f
#endif

/* A space, then the name from a _P function (the plain one off AVR). */
static void name(const char *text) {
  out_char(' ');
  out_flash(text);
}

/* A written reply line (its newline dropped), then how it parses back. */
static void reply(const char *line, size_t length) {
  dp_reply parsed;
  const dp_reply_status status = dp_parse_reply(line, length, &parsed);
  out_bytes(line, (uint16_t)(length - 1));
  out_number(status);
  out_number(parsed.kind);
  out_number(parsed.command);
  out_number(parsed.error);
  out_number(parsed.status.state);
  out_number(parsed.status.laser_on);
  out_bytes(" ", 1);
  out_bytes(parsed.fingerprint, (uint16_t)parsed.fingerprint_length);
  out_char('\n');
}

static void commands(void) {
  int i;
  char line[DP_REPLY_MAX_LENGTH];
  for (i = 0; i <= DP_COMMAND_COUNT; ++i) {
    const dp_command_id id = (dp_command_id)i;
    const dp_command_info *info = dp_command_info_of(id);
    uint8_t frame[DP_WIRE_LENGTH];
    dp_command command = {(dp_command_id)0, 0, 0, 0};
    uint16_t value = 0;
    const bool has_default = dp_command_default(id, &value);
    out_text("command");
    name(FLASH_NAME(dp_command_name)(id));
    out_char(' ');
    out_text(dp_command_name(id));
    out_number(has_default);
    out_number(value);
    if (info == NULL) {
      out_char('\n');
      continue;
    }
    out_number(dp_find_command_by_name(info->name));
    out_number(info->category + info->direction + info->min + info->max + info->target + info->sense);
    out_number(dp_encode(id, info->max, frame));
    out_number(dp_decode(frame, sizeof frame, &command));
    out_number(command.id);
    out_number(command.value);
    out_number(dp_encode(id, (uint16_t)(info->min - 1u), frame));
    out_char(' ');
    out_bytes((const char *)frame, sizeof frame);
    out_char('\n');
    reply(line, dp_write_accepted(&command, (dp_status){dp_states[i % DP_STATE_COUNT], i % 2 == 0}, line));
  }
}

static void errors_states_and_kinds(void) {
  int i;
  char line[DP_REPLY_MAX_LENGTH];
  for (i = 0; i <= DP_ERROR_COUNT + 1; ++i) {
    const dp_error error = (dp_error)i;
    out_text("error");
    name(FLASH_NAME(dp_error_name)(error));
    out_char(' ');
    out_text(dp_error_name(error));
    out_number(dp_error_code(error));
    out_number(dp_error_from_code(dp_error_code(error)));
    out_char('\n');
    if (i >= 1 && i <= DP_ERROR_COUNT) reply(line, dp_write_rejected(error, (dp_status){dp_states[0], true}, line));
  }
  for (i = 0; i <= DP_STATE_COUNT; ++i) {
    const dp_state state = i < DP_STATE_COUNT ? dp_states[i] : (dp_state)0;
    out_text("state");
    name(FLASH_NAME(dp_state_name)(state));
    out_char(' ');
    out_text(dp_state_name(state));
    out_number(dp_state_armed(state));
    out_number(dp_is_state((uint8_t)state));
    out_char('\n');
    if (i < DP_STATE_COUNT) reply(line, dp_write_failsafe((dp_status){state, i % 2 == 1}, line));
  }
  for (i = 0; i <= DP_REPLY_FAILSAFE + 1; ++i) {
    out_text("kind");
    name(FLASH_NAME(dp_reply_prefix)((dp_reply_kind)i));
    out_char(' ');
    out_text(dp_reply_prefix((dp_reply_kind)i));
    out_char('\n');
  }
  reply(line, dp_write_ready(line));
}

/* Every command's frame at its minimum, each after a garbage byte: what the stream parser finds and counts. */
static void stream(void) {
  int i, e;
  uint8_t k;
  dp_stream_parser parser;
  dp_stream_init(&parser);
  for (i = 0; i < DP_COMMAND_COUNT; ++i) {
    uint8_t frame[DP_WIRE_LENGTH];
    dp_command command;
    (void)dp_encode((dp_command_id)i, dp_command_info_of((dp_command_id)i)->min, frame);
    if (dp_stream_feed(&parser, '~', (uint32_t)i, &command)) out_text("early");
    for (k = 0; k < sizeof frame; ++k) {
      if (dp_stream_feed(&parser, frame[k], (uint32_t)i, &command)) {
        out_text("found");
        out_number(command.id);
        out_number(command.value);
        out_char('\n');
      }
    }
  }
  out_text("counts");
  for (e = 1; e <= DP_ERROR_COUNT; ++e) out_number(dp_stream_error_count(&parser, (dp_error)e));
  out_char('\n');
}

int main(void) {
  out_init();
  commands();
  errors_states_and_kinds();
  stream();
  out_text("end\n");
#ifdef __AVR__
  for (;;) {
  }
#else
  return 0;
#endif
}
