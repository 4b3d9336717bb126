// Decode driver of the generated C99 codec: stdin one frame per line in hex (an empty line is a 0-byte frame);
// stdout "ok <command> <value>" or "err <error name>" per line, the format every language's decode driver shares.
#include <drone_protocol.h>
#include <stdio.h>

static int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

int main(void) {
  static char line[1 << 12];
  static uint8_t frame[1 << 11];
  while (fgets(line, sizeof line, stdin) != NULL) {
    size_t n = 0;
    const char *s;
    dp_command command;
    dp_error error;
    for (s = line; hex_digit(s[0]) >= 0 && hex_digit(s[1]) >= 0; s += 2) frame[n++] = (uint8_t)(hex_digit(s[0]) * 16 + hex_digit(s[1]));
    error = dp_decode(frame, n, &command);
    if (error == DP_ERROR_NONE) {
      printf("ok %s %u\n", dp_command_name(command.id), (unsigned)command.value);
    } else {
      printf("err %s\n", dp_error_name(error));
    }
  }
  return 0;
}
