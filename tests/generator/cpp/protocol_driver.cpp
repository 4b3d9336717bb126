// Test driver for the generated DroneProtocol.h: lets the Python tests compare the C++ codec with the Python one.
//
//   protocol_driver decode   stdin: one frame per line in hex (an empty line is a 0-byte frame)
//                            stdout: "ok <command> <category byte> <direction byte> <value>" or "err <error name>"
//   protocol_driver stream   stdin: "<now_ms> <hex bytes>" per line, fed one byte at a time at that time;
//                            "mark" (echoed, to locate frames in the output)
//                            stdout: "frame <hex>" for every frame the StreamParser emits (re-encoded), then
//                            "pending <n>" and one "count <error name> <n>" per parser error kind
//   protocol_driver replies  stdout: the ready line, the accepted line of every command (at its minimum), the
//                            rejected line of every error kind, and the failsafe line of every state, each as
//                            hex; the status cycles through the states in spec order (the command's, error's
//                            or state's index modulo STATE_COUNT), the laser is on at odd indexes
//
// Every result is also checked here: a decoded command re-encodes to the same bytes, lies in its command's
// range and matches its CommandInfo; the parser never holds a full frame. A failed check exits 3.
#include <DroneProtocol.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

using namespace drone_protocol;

static void fail(const char* what, const char* line) {
  fprintf(stderr, "check failed: %s (input: %s)\n", what, line);
  exit(3);
}

static int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Parses hex pairs from `s` until a non-hex character; returns the number of bytes.
static size_t parse_hex(const char* s, uint8_t* out, size_t capacity, const char* line) {
  size_t n = 0;
  while (hex_digit(s[0]) >= 0 && hex_digit(s[1]) >= 0) {
    if (n == capacity) fail("line too long", line);
    out[n++] = static_cast<uint8_t>(hex_digit(s[0]) * 16 + hex_digit(s[1]));
    s += 2;
  }
  return n;
}

static void check_command(const Command& cmd, const uint8_t* expected, const char* line) {
  const CommandInfo info = command_info(cmd.id);
  if (info.category != cmd.category || info.direction != cmd.direction) fail("command_info disagrees", line);
  if (cmd.value < info.min || cmd.value > info.max) fail("value outside the command's range", line);
  uint8_t again[WIRE_LENGTH];
  if (encode(cmd, again) != Error::None) fail("a decoded command does not encode", line);
  if (expected != nullptr && memcmp(again, expected, WIRE_LENGTH) != 0) fail("re-encoding differs", line);
  Command back{};
  if (decode(again, back) != Error::None || back.id != cmd.id || back.value != cmd.value) {
    fail("re-encoded frame does not decode to the same command", line);
  }
}

static int run_decode() {
  static char line[1 << 16];
  static uint8_t frame[1 << 15];
  while (fgets(line, sizeof line, stdin) != nullptr) {
    const size_t n = parse_hex(line, frame, sizeof frame, line);
    Command cmd{};
    const Error error = decode(frame, n, cmd);
    if (error == Error::None) {
      check_command(cmd, frame, line);
      printf("ok %s %u %u %u\n", command_name(cmd.id), static_cast<unsigned>(cmd.category),
             static_cast<unsigned>(cmd.direction), static_cast<unsigned>(cmd.value));
    } else {
      printf("err %s\n", error_name(error));
    }
  }
  return 0;
}

static int run_stream() {
  static char line[1 << 16];
  static uint8_t bytes[1 << 15];
  StreamParser parser;
  while (fgets(line, sizeof line, stdin) != nullptr) {
    if (strncmp(line, "mark", 4) == 0) {
      printf("mark\n");
      continue;
    }
    char* rest = nullptr;
    const unsigned long now = strtoul(line, &rest, 10);
    while (*rest == ' ') ++rest;
    const size_t n = parse_hex(rest, bytes, sizeof bytes, line);
    for (size_t i = 0; i < n; ++i) {
      if (parser.feed(bytes[i], static_cast<uint32_t>(now))) {
        if (parser.pending() != 0) fail("bytes pending right after a frame", line);
        check_command(parser.command(), nullptr, line);
        uint8_t out[WIRE_LENGTH];
        encode(parser.command(), out);
        printf("frame ");
        for (uint8_t k = 0; k < WIRE_LENGTH; ++k) printf("%02x", out[k]);
        printf("\n");
      }
      if (parser.pending() >= WIRE_LENGTH) fail("pending() holds a full frame", line);
    }
  }
  printf("pending %u\n", static_cast<unsigned>(parser.pending()));
  for (uint8_t e = 1; e <= PARSER_ERROR_COUNT; ++e) {
    printf("count %s %u\n", error_name(static_cast<Error>(e)), static_cast<unsigned>(parser.error_count(static_cast<Error>(e))));
  }
  return 0;
}

static void print_line(const char* line, uint8_t n) {
  if (n == 0 || n > REPLY_MAX_LENGTH || line[n - 1] != '\n') fail("reply line without its newline", line);
  for (uint8_t i = 0; i < n; ++i) printf("%02x", static_cast<unsigned>(static_cast<uint8_t>(line[i])));
  printf("\n");
}

static int run_replies() {
  char line[REPLY_MAX_LENGTH + 8];
  print_line(line, write_ready(line));
  for (CommandIndex i = 0; i < COMMAND_COUNT; ++i) {
    const CommandInfo info = command_info(static_cast<CommandId>(i));
    const Command cmd{static_cast<CommandId>(i), info.category, info.direction, info.min};
    print_line(line, write_accepted(cmd, static_cast<State>(i % STATE_COUNT), i % 2 == 1, line));
  }
  for (uint8_t e = 1; e <= ERROR_COUNT; ++e) {
    print_line(line, write_rejected(static_cast<Error>(e), static_cast<State>(e % STATE_COUNT), e % 2 == 1, line));
  }
  for (uint8_t s = 0; s < STATE_COUNT; ++s) print_line(line, write_failsafe(static_cast<State>(s), s % 2 == 1, line));
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 2 && strcmp(argv[1], "replies") == 0) return run_replies();
  if (argc == 2 && strcmp(argv[1], "decode") == 0) return run_decode();
  if (argc == 2 && strcmp(argv[1], "stream") == 0) return run_stream();
  fprintf(stderr, "usage: %s decode|stream\n", argv[0]);
  return 2;
}
