// Stream driver of the generated C99 codec, in the format every language's driver shares:
// stdin "<now_ms> <hex bytes>" per line; stdout "<command name> <value>" per command found, then
// "errors <name>=<count> ..." with every error kind of the spec, in spec order.
#include <drone_protocol.h>
#include <stdio.h>
#include <stdlib.h>

static int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

int main(void) {
  static char line[1 << 16];
  static char out[1 << 16];
  dp_stream_parser parser = DP_STREAM_PARSER_INIT;
  dp_command command;
  int e;
  setvbuf(stdout, out, _IOFBF, sizeof out);
  while (fgets(line, sizeof line, stdin) != NULL) {
    char *s = NULL;
    const uint32_t now = (uint32_t)strtoul(line, &s, 10);
    while (*s == ' ') ++s;
    for (; hex_digit(s[0]) >= 0 && hex_digit(s[1]) >= 0; s += 2) {
      if (dp_stream_feed(&parser, (uint8_t)(hex_digit(s[0]) * 16 + hex_digit(s[1])), now, &command)) {
        printf("%s %u\n", dp_command_name(command.id), (unsigned)command.value);
      }
    }
  }
  printf("errors");
  for (e = 1; e <= DP_ERROR_COUNT; ++e) {
    printf(" %s=%u", dp_error_name((dp_error)e), (unsigned)dp_stream_error_count(&parser, (dp_error)e));
  }
  printf("\n");
  return 0;
}
