/* Reply driver of the generated C99 codec: stdin one line per input line in hex; stdout what dp_parse_reply() made
   of it, "ready <protocol> <fingerprint> <integrity>", "ok <kind>", "malformed <kind>", "unknown" or "bad_check",
   the format every language's reply driver shares. */
#include <drone_protocol.h>
#include <stdio.h>
#include <string.h>

static const char *const KINDS[] = {"ready", "accepted", "rejected", "failsafe"};

int main(void) {
  static char hex[8192], line[4096];
  while (fgets(hex, sizeof hex, stdin) != NULL) {
    size_t n = 0, i;
    dp_reply reply;
    dp_reply_status status;
    for (i = 0; hex[i] != '\0' && hex[i] != '\n' && hex[i + 1] != '\0' && n < sizeof line; i += 2) {
      unsigned byte;
      if (sscanf(hex + i, "%2x", &byte) != 1) return 2;
      line[n++] = (char)byte;
    }
    status = dp_parse_reply(line, n, &reply);
    if (status == DP_REPLY_OK && reply.kind == DP_REPLY_READY) {
      printf("ready %.*s %.*s %.*s\n", (int)reply.protocol_length, reply.protocol, (int)reply.fingerprint_length,
             reply.fingerprint, (int)reply.integrity_length, reply.integrity);
    } else if (status == DP_REPLY_OK) {
      printf("ok %s\n", KINDS[reply.kind]);
    } else if (status == DP_REPLY_MALFORMED) {
      printf("malformed %s\n", dp_reply_prefix(reply.kind));
    } else {
      printf("%s\n", status == DP_REPLY_UNKNOWN ? "unknown" : "bad_check");
    }
  }
  return 0;
}
