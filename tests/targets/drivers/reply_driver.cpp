// Reply driver of the generated C++ library: stdin one line per input line in hex; stdout what parse_reply() made
// of it, "ready <protocol> <fingerprint> <integrity>", "ok <kind>", "malformed <prefix>", "unknown" or "bad_check",
// the format every language's reply driver shares.
#include <DroneProtocol.h>
#include <cstdio>

using namespace drone_protocol;

int main() {
  static const char* const KINDS[] = {"ready", "accepted", "rejected", "failsafe"};
  static_assert(sizeof KINDS / sizeof KINDS[0] == REPLY_KIND_COUNT, "a name per kind");
  static char hex[8192], line[4096];
  while (std::fgets(hex, sizeof hex, stdin) != nullptr) {
    size_t n = 0;
    for (size_t i = 0; hex[i] != '\0' && hex[i] != '\n' && hex[i + 1] != '\0' && n < sizeof line; i += 2) {
      unsigned byte;
      if (std::sscanf(hex + i, "%2x", &byte) != 1) return 2;
      line[n++] = static_cast<char>(byte);
    }
    Reply reply;
    const ReplyError error = parse_reply(line, n, reply);
    if (error == ReplyError::None && reply.kind == ReplyKind::Ready) {
      std::printf("ready %.*s %.*s %.*s\n", static_cast<int>(reply.protocol_length), reply.protocol,
                  static_cast<int>(reply.fingerprint_length), reply.fingerprint,
                  static_cast<int>(reply.integrity_length), reply.integrity);
    } else if (error == ReplyError::None) {
      std::printf("ok %s\n", KINDS[static_cast<uint8_t>(reply.kind)]);
    } else if (error == ReplyError::Malformed) {
      std::printf("malformed %s\n", reply_prefix(reply.kind));
    } else {
      std::printf("%s\n", reply_error_name(error));
    }
  }
  return 0;
}
