// The C99 codec at its smallest on the ATmega328P: encode one frame, decode it, and send the frame and what was
// decoded over the UART. tests/targets/test_targets_c_avr.py measures its static RAM with avr-size and runs it in
// simavr; COMMAND and VALUE come from the test (a command of the spec and a value in its range).
#include "drone_protocol.h"
#include "out.h"

int main(void) {
  uint8_t frame[DP_WIRE_LENGTH];
  dp_command command = {(dp_command_id)0, 0, 0, 0};
  dp_error encoded, decoded = DP_ERROR_NONE;
  out_init();
  encoded = dp_encode(COMMAND, VALUE, frame);
  if (encoded == DP_ERROR_NONE) decoded = dp_decode(frame, sizeof frame, &command);
  out_bytes((const char *)frame, encoded == DP_ERROR_NONE ? sizeof frame : 0);
  out_number(encoded);
  out_number(decoded);
  out_number(command.id == COMMAND);
  out_number(command.value);
  out_char('\n');
  for (;;) {
  }
}
