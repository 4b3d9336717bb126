// The Arduino C++ StreamParser (host build) on the same stream, for the callgrind comparison.
#include <DroneProtocol.h>

#include <stdio.h>

extern "C" size_t bench_stream(const uint8_t* bytes, size_t len);
extern "C" __attribute__((noinline)) size_t bench_stream(const uint8_t* bytes, size_t len) {
  drone_protocol::StreamParser parser;
  size_t found = 0;
  for (size_t i = 0; i < len; ++i) found += parser.feed(bytes[i], 0);
  return found;
}

int main(int argc, char** argv) {
  static uint8_t stream[1 << 24];
  FILE* f = argc == 2 ? fopen(argv[1], "rb") : nullptr;
  if (f == nullptr) return 2;
  const size_t len = fread(stream, 1, sizeof stream, f);
  fclose(f);
  printf("%zu\n", bench_stream(stream, len));
  return 0;
}
