// libFuzzer target for the generated DroneProtocol.h: StreamParser, decode, encode and parse_reply.
//
// Input: a byte stream fed to a StreamParser one byte at a time. 0xFF n advances the clock by n ms (0xFF 0xFF
// feeds 0xFF itself), so inter-byte timeouts are explored too. The same input also drives decode() on every
// 6-byte window and on the whole input, and encode() on (command, value) triples read from it.
//
// Invariants checked (a failure aborts, which libFuzzer reports as a crash):
// - the parser agrees after every byte with a small reference model written from the spec's rules (same frames,
//   same pending bytes, same error counts by kind);
// - pending() <= WIRE_LENGTH - 1; a frame is emitted only when its last byte arrives, and it is exactly the
//   last WIRE_LENGTH bytes fed (the frame and, with integrity crc8, its check);
// - every emitted or decoded command lies in its command's range, matches its CommandInfo and re-encodes to
//   the same bytes; encode() succeeds exactly for values in range, and its frame decodes back;
// - error_name()/error_code() are total;
// - parse_reply() of the input as a reply line: a line it accepts is exactly the line the writers write for what
//   it read (its ready fields lie inside the input), and every line the writers write reads back as written.
#include <DroneProtocol.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

using namespace drone_protocol;

#define CHECK(cond)                                                              \
  do {                                                                           \
    if (!(cond)) {                                                               \
      fprintf(stderr, "invariant failed at %s:%d: %s\n", __FILE__, __LINE__, #cond); \
      abort();                                                                   \
    }                                                                            \
  } while (0)

namespace {

// The command with these two bytes, by a plain scan of command_info() (independent of the parser's tables).
int find(uint8_t category, uint8_t direction) {
  for (CommandIndex i = 0; i < COMMAND_COUNT; ++i) {
    const CommandInfo info = command_info(static_cast<CommandId>(i));
    if (info.category == category && info.direction == direction) return i;
  }
  return -1;
}

bool is_category(uint8_t byte) {
  for (CommandIndex i = 0; i < COMMAND_COUNT; ++i) {
    if (command_info(static_cast<CommandId>(i)).category == byte) return true;
  }
  return false;
}

// CRC-8/SMBUS bit by bit (independent of the header's nibble table).
uint8_t crc8_bitwise(const uint8_t* data, uint8_t n) {
  uint8_t crc = 0;
  for (uint8_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (uint8_t b = 0; b < 8; ++b) crc = static_cast<uint8_t>(crc & 0x80 ? (crc << 1) ^ 0x07 : crc << 1);
  }
  return crc;
}

// The Error value of bad_check (only met with integrity crc8).
constexpr uint8_t BAD_CHECK = static_cast<uint8_t>(Error::BadCheck);

// The first problem of buf[0..len) read as the start of a frame; Error::None if it may still become one.
Error first_error(const uint8_t* buf, uint8_t len) {
  if (len >= 1 && !is_category(buf[0])) return Error::BadCategory;
  if (len >= 2 && find(buf[0], buf[1]) < 0) return Error::BadDirection;
  for (uint8_t i = 2; i < len && i < FRAME_LENGTH; ++i) {
    if (buf[i] < '0' || buf[i] > '9') return Error::BadDigit;
  }
  for (uint8_t i = FRAME_LENGTH; i < len; ++i) {
    const uint8_t crc = crc8_bitwise(buf, FRAME_LENGTH);
    const uint8_t nibble = i == FRAME_LENGTH ? crc >> 4 : crc & 0x0F;
    if (buf[i] != "0123456789ABCDEF"[nibble]) return static_cast<Error>(BAD_CHECK);
  }
  if (len == WIRE_LENGTH) {
    uint32_t value = 0;
    for (uint8_t i = 2; i < FRAME_LENGTH; ++i) value = value * 10 + (buf[i] - '0');
    const CommandInfo info = command_info(static_cast<CommandId>(find(buf[0], buf[1])));
    if (value < info.min || value > info.max) return Error::OutOfRange;
  }
  return Error::None;
}

// The reference: the rules of the spec, written plainly (re-check everything after every slide).
struct Reference {
  uint8_t buf[WIRE_LENGTH];
  uint8_t len = 0;
  uint32_t last_ms = 0;
  uint32_t counts[ERROR_COUNT + 1] = {};
  uint8_t frame[WIRE_LENGTH];

  bool feed(uint8_t byte, uint32_t now) {
    if (len > 0 && now - last_ms > INTER_BYTE_TIMEOUT_MS) {
      ++counts[static_cast<uint8_t>(Error::Timeout)];
      len = 0;
    }
    last_ms = now;
    buf[len++] = byte;
    while (len > 0) {
      const Error e = first_error(buf, len);
      if (e == Error::None) {
        if (len < WIRE_LENGTH) return false;
        memcpy(frame, buf, WIRE_LENGTH);
        len = 0;
        return true;
      }
      ++counts[static_cast<uint8_t>(e)];
      memmove(buf, buf + 1, --len);
    }
    return false;
  }
};

void check_command(const Command& cmd, const uint8_t* bytes) {
  CHECK(static_cast<CommandIndex>(cmd.id) < COMMAND_COUNT);
  const CommandInfo info = command_info(cmd.id);
  CHECK(info.category == cmd.category && info.direction == cmd.direction);
  CHECK(cmd.value >= info.min && cmd.value <= info.max);
  CHECK(command_name(cmd.id) != nullptr && strcmp(command_name(cmd.id), "unknown") != 0);
  uint8_t again[WIRE_LENGTH];
  CHECK(encode(cmd, again) == Error::None);
  CHECK(memcmp(again, bytes, WIRE_LENGTH) == 0);
  Command back{};
  CHECK(decode(again, back) == Error::None);
  CHECK(back.id == cmd.id && back.value == cmd.value && back.category == cmd.category &&
        back.direction == cmd.direction);
}

void fuzz_stream(const uint8_t* data, size_t size) {
  StreamParser parser;
  Reference ref;
  uint8_t recent[WIRE_LENGTH] = {};  // the last bytes fed, oldest first
  uint32_t now = 0;
  for (size_t i = 0; i < size; ++i) {
    uint8_t byte = data[i];
    if (byte == 0xFF && i + 1 < size) {
      ++i;
      if (data[i] != 0xFF) {
        now += data[i];
        continue;
      }
    }
    memmove(recent, recent + 1, WIRE_LENGTH - 1);
    recent[WIRE_LENGTH - 1] = byte;
    const bool got = parser.feed(byte, now);
    const bool expected = ref.feed(byte, now);
    CHECK(got == expected);
    CHECK(parser.pending() == ref.len);
    CHECK(parser.pending() <= WIRE_LENGTH - 1);
    for (uint8_t e = 1; e <= ERROR_COUNT; ++e) {
      const uint32_t n = ref.counts[e] > 0xFFFF ? 0xFFFF : ref.counts[e];
      CHECK(parser.error_count(static_cast<Error>(e)) == n);
    }
    if (got) {
      CHECK(parser.pending() == 0);
      CHECK(memcmp(ref.frame, recent, WIRE_LENGTH) == 0);
      check_command(parser.command(), recent);
    }
  }
  parser.reset();
  CHECK(parser.pending() == 0);
  for (uint8_t e = 1; e <= ERROR_COUNT; ++e) CHECK(parser.error_count(static_cast<Error>(e)) == 0);
}

void fuzz_decode(const uint8_t* data, size_t size) {
  Command cmd{};
  const Error whole = decode(data, size, cmd);
  if (size < WIRE_LENGTH) CHECK(whole == Error::TooShort);
  if (size > WIRE_LENGTH) CHECK(whole == Error::TooLong);
  for (size_t at = 0; at + WIRE_LENGTH <= size && at < 64; ++at) {
    Command out{};
    const Error e = decode(data + at, out);
    CHECK(e == first_error(data + at, WIRE_LENGTH));
    if (e == Error::None) check_command(out, data + at);
  }
}

void fuzz_encode(const uint8_t* data, size_t size) {
  for (size_t at = 0; at + 3 <= size && at < 48; at += 3) {
    const CommandId id = static_cast<CommandId>((data[at] << 8 | data[at + 1]) % COMMAND_COUNT);
    const uint16_t value = static_cast<uint16_t>(data[at + 1] << 8 | data[at + 2]);
    const CommandInfo info = command_info(id);
    uint8_t frame[WIRE_LENGTH];
    const Error e = encode(id, value, frame);
    CHECK((e == Error::None) == (value >= info.min && value <= info.max));
    if (e != Error::None) {
      CHECK(e == Error::OutOfRange);
      continue;
    }
    Command cmd{};
    CHECK(decode(frame, cmd) == Error::None);
    CHECK(cmd.id == id && cmd.value == value);
    check_command(cmd, frame);
  }
  // A CommandId outside the table is refused, not read out of bounds.
  uint8_t frame[WIRE_LENGTH];
  CHECK(encode(static_cast<CommandId>(COMMAND_COUNT), 0, frame) != Error::None);
}

void fuzz_names(const uint8_t* data, size_t size) {
  if (size == 0) return;
  const Error e = static_cast<Error>(data[0]);
  CHECK(error_name(e) != nullptr);
  const char code = error_code(e);
  CHECK(code >= 0x21 && code <= 0x7E);
  char line[64];
  const State state = static_cast<State>(size > 1 ? data[1] % STATE_COUNT : 0);
  const uint8_t n = write_rejected(e, state, size > 2 && (data[2] & 1), line);
  CHECK(n >= 2 && n <= REPLY_MAX_LENGTH && line[n - 1] == '\n');
  CHECK(state_code(state) != '?');
  CHECK(strcmp(state_name(state), "unknown") != 0);
}

// parse_reply() of the input: what it accepts, the writers write again byte for byte (CR/LF aside).
void fuzz_replies(const uint8_t* data, size_t size) {
  const char* line = reinterpret_cast<const char*>(data);
  Reply reply;
  const ReplyError error = parse_reply(line, size, reply);
  CHECK(strcmp(reply_error_name(error), "unknown") != 0 || error == ReplyError::Unknown);
  if (error != ReplyError::None) return;
  size_t length = size;
  while (length > 0 && (line[length - 1] == '\n' || line[length - 1] == '\r')) --length;
  char out[REPLY_MAX_LENGTH];
  uint8_t n = 0;
  switch (reply.kind) {
    case ReplyKind::Ready: {
      const char* const fields[] = {reply.protocol, reply.fingerprint, reply.integrity};
      const size_t lengths[] = {reply.protocol_length, reply.fingerprint_length, reply.integrity_length};
      for (uint8_t i = 0; i < 3; ++i) CHECK(fields[i] > line && fields[i] + lengths[i] <= line + length);
      const bool own = lengths[0] == strlen(PROTOCOL_NAME) && memcmp(fields[0], PROTOCOL_NAME, lengths[0]) == 0 &&
                       lengths[1] == strlen(SPEC_FINGERPRINT) && memcmp(fields[1], SPEC_FINGERPRINT, lengths[1]) == 0 &&
                       lengths[2] == strlen(INTEGRITY) && memcmp(fields[2], INTEGRITY, lengths[2]) == 0;
      if (!own) return;
      n = write_ready(out);
      break;
    }
    case ReplyKind::Accepted: {
      const CommandInfo info = command_info(reply.command);
      Command command{};
      command.category = info.category;
      command.direction = info.direction;
      n = write_accepted(command, reply.state, reply.laser, out);
      break;
    }
    case ReplyKind::Rejected:
      n = write_rejected(reply.error, reply.state, reply.laser, out);
      break;
    case ReplyKind::Failsafe:
      n = write_failsafe(reply.state, reply.laser, out);
      break;
  }
  CHECK(n >= 1 && out[n - 1] == '\n' && n - 1u == length && memcmp(out, line, length) == 0);
}

// Every line the writers write reads back as written.
void fuzz_written_replies(const uint8_t* data, size_t size) {
  if (size < 3) return;
  const State state = static_cast<State>(data[0] % STATE_COUNT);
  const bool laser = (data[1] & 1) != 0;
  const Error error = static_cast<Error>(1 + data[2] % ERROR_COUNT);
  char out[REPLY_MAX_LENGTH];
  Reply reply;
  uint8_t n = write_rejected(error, state, laser, out);
  CHECK(parse_reply(out, n, reply) == ReplyError::None && reply.kind == ReplyKind::Rejected);
  CHECK(reply.error == error && reply.state == state && reply.laser == laser);
  n = write_failsafe(state, laser, out);
  CHECK(parse_reply(out, n, reply) == ReplyError::None && reply.kind == ReplyKind::Failsafe);
  CHECK(reply.state == state && reply.laser == laser);
  const CommandId id = static_cast<CommandId>(data[2] % COMMAND_COUNT);
  Command command{};
  command.category = command_info(id).category;
  command.direction = command_info(id).direction;
  n = write_accepted(command, state, laser, out);
  CHECK(parse_reply(out, n, reply) == ReplyError::None && reply.kind == ReplyKind::Accepted);
  CHECK(reply.command == id && reply.state == state && reply.laser == laser);
  n = write_ready(out);
  CHECK(parse_reply(out, n, reply) == ReplyError::None && reply.kind == ReplyKind::Ready);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  fuzz_stream(data, size);
  fuzz_decode(data, size);
  fuzz_encode(data, size);
  fuzz_names(data, size);
  fuzz_replies(data, size);
  fuzz_written_replies(data, size);
  return 0;
}
