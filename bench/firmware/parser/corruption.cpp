// Spurious frames under byte corruption (host build of the generated StreamParser): a stream of valid frames
// (uniform over the spec's commands, values uniform in range) has each byte replaced by a random one with
// probability P; every frame the parser emits that is not a sent frame received intact is spurious. Spurious
// frames of the commands a corrupted link must never invent (arm, disarm, the laser, the self-test, land) are
// counted apart as dangerous.
//
//   corruption FRAMES PERCENT SEED   ->  "frames N corrupted_frames N emitted N spurious N dangerous N"
#include <DroneProtocol.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

namespace dp = drone_protocol;

namespace {

uint64_t state;
uint32_t next() {  // xorshift64*
  state ^= state >> 12;
  state ^= state << 25;
  state ^= state >> 27;
  return static_cast<uint32_t>((state * 2685821657736338717ULL) >> 32);
}

bool dangerous(dp::CommandId id) {
  const char* name = dp::command_name(id);
  static const char* const kinds[] = {"arm", "disarm", "first_test", "land"};
  for (const char* k : kinds) {
    if (strcmp(name, k) == 0) return true;
  }
  return dp::command_info(id).category == static_cast<uint8_t>(dp::Category::Laser);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s FRAMES PERCENT SEED\n", argv[0]);
    return 2;
  }
  const unsigned long frames = strtoul(argv[1], nullptr, 10);
  const double p = strtod(argv[2], nullptr) / 100.0;
  state = strtoull(argv[3], nullptr, 10) | 1;
  const uint32_t threshold = static_cast<uint32_t>(p * 4294967295.0);
  dp::StreamParser parser;
  uint8_t sent[dp::WIRE_LENGTH];
  bool intact = false;  // the frame being fed so far arrived unchanged
  unsigned long corrupted_frames = 0, emitted = 0, spurious = 0, bad = 0;
  uint32_t now = 0;
  for (unsigned long f = 0; f < frames; ++f) {
    const dp::CommandId id = static_cast<dp::CommandId>(next() % dp::COMMAND_COUNT);
    const dp::CommandInfo info = dp::command_info(id);
    const uint16_t value = static_cast<uint16_t>(info.min + next() % (info.max - info.min + 1u));
    dp::encode(id, value, sent);
    bool changed = false;
    for (uint8_t i = 0; i < dp::WIRE_LENGTH; ++i) {
      uint8_t byte = sent[i];
      if (next() <= threshold && threshold != 0) {
        byte = static_cast<uint8_t>(next());
        changed |= byte != sent[i];
      }
      intact = (i == 0 ? true : intact) && byte == sent[i];
      if (parser.feed(byte, now)) {
        ++emitted;
        // A true frame: the whole sent frame arrived unchanged and this is its last byte.
        const bool genuine = intact && i == dp::WIRE_LENGTH - 1;
        if (!genuine) {
          ++spurious;
          if (dangerous(parser.command().id)) ++bad;
        }
      }
    }
    corrupted_frames += changed;
    now += 2;  // 50 Hz would be 20 ms; a short gap keeps partial frames alive across frames (the worst case)
  }
  printf("frames %lu corrupted_frames %lu emitted %lu spurious %lu dangerous %lu\n", frames, corrupted_frames,
         emitted, spurious, bad);
  return 0;
}
