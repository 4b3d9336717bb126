// The stream rules of the spec written plainly, for the C tests and the C fuzz target: re-check the whole buffer
// after every byte and every slide, find commands by a scan of dp_command_info_of() (not the codec's switches).
#ifndef TESTS_TARGETS_C_REFERENCE_H
#define TESTS_TARGETS_C_REFERENCE_H

#include <drone_protocol.h>
#include <string.h>

typedef struct reference {
  uint8_t buffer[DP_WIRE_LENGTH];
  uint8_t length;
  uint32_t last_ms;
  uint32_t counts[DP_ERROR_COUNT + 1];
  uint8_t frame[DP_WIRE_LENGTH]; /* the last frame found */
} reference;

#if DP_CHECK_LENGTH > 0
/* The upper-case hex digits of the crc8 check of data[0..length). */
static void reference_check(const uint8_t *data, size_t length, uint8_t out[2]) {
  static const char digits[] = "0123456789ABCDEF";
  uint8_t crc = 0;
  size_t i;
  int bit;
  for (i = 0; i < length; ++i) {
    crc ^= data[i];
    for (bit = 0; bit < 8; ++bit) crc = (uint8_t)(crc & 0x80 ? (crc << 1) ^ 0x07 : crc << 1);
  }
  out[0] = (uint8_t)digits[crc >> 4];
  out[1] = (uint8_t)digits[crc & 15];
}
#endif

static int reference_find(uint8_t category, uint8_t direction) {
  int i;
  for (i = 0; i < DP_COMMAND_COUNT; ++i) {
    const dp_command_info *info = dp_command_info_of((dp_command_id)i);
    if (info->category == category && info->direction == direction) return i;
  }
  return -1;
}

static bool reference_is_category(uint8_t byte) {
  int i;
  for (i = 0; i < DP_COMMAND_COUNT; ++i) {
    if (dp_command_info_of((dp_command_id)i)->category == byte) return true;
  }
  return false;
}

/* The first problem of buf[0..len) read as the start of a frame; DP_ERROR_NONE if it may still become one. */
static dp_error reference_first_error(const uint8_t *buf, uint8_t len) {
  uint8_t i;
  if (len >= 1 && !reference_is_category(buf[0])) return DP_ERROR_BAD_CATEGORY;
  if (len >= 2 && reference_find(buf[0], buf[1]) < 0) return DP_ERROR_BAD_DIRECTION;
  for (i = 2; i < len && i < DP_FRAME_LENGTH; ++i) {
    if (buf[i] < '0' || buf[i] > '9') return DP_ERROR_BAD_DIGIT;
  }
#if DP_CHECK_LENGTH > 0
  if (len > DP_FRAME_LENGTH) { /* each check digit as it arrives */
    uint8_t check[2];
    reference_check(buf, DP_FRAME_LENGTH, check);
    if (memcmp(check, buf + DP_FRAME_LENGTH, (size_t)(len - DP_FRAME_LENGTH)) != 0) return DP_ERROR_BAD_CHECK;
  }
#endif
  if (len == DP_WIRE_LENGTH) { /* the range, once the whole frame is in */
    uint32_t value = 0;
    const dp_command_info *info = dp_command_info_of((dp_command_id)reference_find(buf[0], buf[1]));
    for (i = 2; i < DP_FRAME_LENGTH; ++i) value = value * 10u + (uint32_t)(buf[i] - '0');
    if (value < info->min || value > info->max) return DP_ERROR_OUT_OF_RANGE;
  }
  return DP_ERROR_NONE;
}

static bool reference_feed(reference *ref, uint8_t byte, uint32_t now) {
  if (ref->length > 0 && now - ref->last_ms > DP_INTER_BYTE_TIMEOUT_MS) {
    ++ref->counts[DP_ERROR_TIMEOUT];
    ref->length = 0;
  }
  ref->last_ms = now;
  ref->buffer[ref->length++] = byte;
  while (ref->length > 0) {
    const dp_error e = reference_first_error(ref->buffer, ref->length);
    if (e == DP_ERROR_NONE) {
      if (ref->length < DP_WIRE_LENGTH) return false;
      memcpy(ref->frame, ref->buffer, DP_WIRE_LENGTH);
      ref->length = 0;
      return true;
    }
    ++ref->counts[e];
    memmove(ref->buffer, ref->buffer + 1, --ref->length);
  }
  return false;
}

#endif
