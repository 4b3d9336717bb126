// Stream driver of the generated Arduino C++ header (host build), in the format every language's driver shares:
// stdin "<now_ms> <hex bytes>" per line; stdout "<command name> <value>" per command found, then
// "errors <name>=<count> ..." with every error kind of the spec, in spec order.
#include <DroneProtocol.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

using namespace drone_protocol;

static int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

int main() {
  static char line[1 << 16];
  static char out[1 << 16];
  setvbuf(stdout, out, _IOFBF, sizeof out);
  StreamParser parser;
  while (fgets(line, sizeof line, stdin) != nullptr) {
    char* s = nullptr;
    const uint32_t now = static_cast<uint32_t>(strtoul(line, &s, 10));
    while (*s == ' ') ++s;
    for (; hex_digit(s[0]) >= 0 && hex_digit(s[1]) >= 0; s += 2) {
      if (parser.feed(static_cast<uint8_t>(hex_digit(s[0]) * 16 + hex_digit(s[1])), now)) {
        printf("%s %u\n", command_name(parser.command().id), static_cast<unsigned>(parser.command().value));
      }
    }
  }
  printf("errors");
  for (uint8_t e = 1; strcmp(error_name(static_cast<Error>(e)), "unknown") != 0; ++e) {
    printf(" %s=%u", error_name(static_cast<Error>(e)), static_cast<unsigned>(parser.error_count(static_cast<Error>(e))));
  }
  printf("\n");
  return 0;
}
