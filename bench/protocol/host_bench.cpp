// Host throughput of the generated StreamParser + dispatch against minimal baselines, on one stream of frames.
//
//   host_bench time [frames] [passes]   best-of-passes timing: prints key=value lines
//   host_bench parser|naive|memcpy [frames]   one pass of one loop (run under callgrind with --toggle-collect)
//
// The stream is a realistic mix of valid frames (keep-alives, moves at default and other speeds, servo steps,
// laser and init commands), built by a fixed LCG so every run and every tool sees the same bytes.
#include <DroneProtocol.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace dp = drone_protocol;

namespace {

uint32_t lcg_state = 12345u;
uint32_t lcg() {
  lcg_state = lcg_state * 1664525u + 1013904223u;
  return lcg_state >> 8;
}

std::vector<uint8_t> make_stream(size_t frames) {
  std::vector<uint8_t> out(frames * dp::FRAME_LENGTH);
  for (size_t f = 0; f < frames; ++f) {
    const uint32_t r = lcg() % 100u;
    dp::CommandId id;
    uint16_t value;
    if (r < 40) {
      id = dp::CommandId::HoldAltitude;  // the pilot's keep-alive
      value = 0;
    } else {
      const uint8_t i = static_cast<uint8_t>(lcg() % dp::COMMAND_COUNT);
      id = static_cast<dp::CommandId>(i);
      const dp::CommandInfo info = dp::command_info(id);
      if (info.has_default && (r < 70 || info.min == info.max)) {
        value = info.default_value;
      } else {
        value = static_cast<uint16_t>(info.min + lcg() % (info.max - info.min + 1u));
      }
    }
    if (dp::encode(id, value, &out[f * dp::FRAME_LENGTH]) != dp::Error::None) std::abort();
  }
  return out;
}

// Handlers: one per category; each folds the command into a checksum so nothing is optimised away.
struct Sink {
  uint32_t sum = 0;
  void on_move(const dp::Command& c) { sum += c.value; }
  void on_turn(const dp::Command& c) { sum += c.value * 3u; }
  void on_servo(const dp::Command& c) { sum += c.value * 5u + c.direction; }
  void on_laser(const dp::Command& c) { sum ^= c.category; }
  void on_init(const dp::Command& c) { sum += c.direction; }
};

}  // namespace

// The measured loops: extern "C" and noinline so callgrind can collect exactly them (--toggle-collect).
extern "C" __attribute__((noinline)) uint32_t bench_parser(const uint8_t* data, size_t n) {
  dp::StreamParser parser;
  Sink sink;
  uint32_t now = 0;
  for (size_t i = 0; i < n; ++i) {
    if (parser.feed(data[i], now)) {
      dp::dispatch(parser.command(), sink);
      ++now;  // one millisecond per frame: never an inter-byte timeout
    }
  }
  return sink.sum + parser.error_count(dp::Error::BadCategory);
}

// Baseline: trusts the framing, no validation, no table lookup: two bytes and a 4-digit atoi per 6 bytes.
extern "C" __attribute__((noinline)) uint32_t bench_naive(const uint8_t* data, size_t n) {
  uint32_t sum = 0;
  for (size_t i = 0; i + 6 <= n; i += 6) {
    const uint32_t value = (data[i + 2] - '0') * 1000u + (data[i + 3] - '0') * 100u + (data[i + 4] - '0') * 10u +
                           (data[i + 5] - '0');
    sum += value + data[i] + data[i + 1];
  }
  return sum;
}

static uint8_t* volatile memcpy_target;
extern "C" __attribute__((noinline)) uint32_t bench_memcpy(const uint8_t* data, size_t n) {
  memcpy(memcpy_target, data, n);
  return memcpy_target[n / 2];
}

using Loop = uint32_t (*)(const uint8_t*, size_t);

static double best_seconds(Loop loop, const std::vector<uint8_t>& stream, int passes, uint32_t* check) {
  double best = 1e30;
  for (int p = 0; p < passes; ++p) {
    const auto t0 = std::chrono::steady_clock::now();
    *check += loop(stream.data(), stream.size());
    const auto t1 = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(t1 - t0).count();
    if (s < best) best = s;
  }
  return best;
}

int main(int argc, char** argv) {
  const char* mode = argc > 1 ? argv[1] : "time";
  const size_t frames = argc > 2 ? static_cast<size_t>(std::strtoul(argv[2], nullptr, 10)) : 100000u;
  const int passes = argc > 3 ? std::atoi(argv[3]) : 200;
  const std::vector<uint8_t> stream = make_stream(frames);
  std::vector<uint8_t> target(stream.size());
  memcpy_target = target.data();

  // Correctness first: the parser must find every frame (inline here, so the measured loops run once per pass).
  {
    dp::StreamParser parser;
    size_t found = 0;
    for (size_t i = 0; i < stream.size(); ++i) found += parser.feed(stream[i], 0);
    if (found != frames) {
      std::fprintf(stderr, "parser found %zu of %zu frames\n", found, frames);
      return 1;
    }
  }

  uint32_t check = 0;
  if (std::strcmp(mode, "time") == 0) {
    // Interleave the loops pass by pass so that drift on a shared machine hits them alike.
    double parser_s = 1e30, naive_s = 1e30, memcpy_s = 1e30;
    for (int p = 0; p < passes; ++p) {
      parser_s = std::min(parser_s, best_seconds(bench_parser, stream, 1, &check));
      naive_s = std::min(naive_s, best_seconds(bench_naive, stream, 1, &check));
      memcpy_s = std::min(memcpy_s, best_seconds(bench_memcpy, stream, 1, &check));
    }
    const double mb = static_cast<double>(stream.size()) / 1e6;
    std::printf("frames=%zu\nbytes=%zu\npasses=%d\n", frames, stream.size(), passes);
    std::printf("parser_s=%.9f\nnaive_s=%.9f\nmemcpy_s=%.9f\n", parser_s, naive_s, memcpy_s);
    std::printf("parser_frames_per_s=%.0f\nnaive_frames_per_s=%.0f\n", frames / parser_s, frames / naive_s);
    std::printf("parser_mb_per_s=%.2f\nnaive_mb_per_s=%.2f\nmemcpy_mb_per_s=%.2f\n", mb / parser_s, mb / naive_s,
                mb / memcpy_s);
  } else if (std::strcmp(mode, "parser") == 0) {
    check += bench_parser(stream.data(), stream.size());
  } else if (std::strcmp(mode, "naive") == 0) {
    check += bench_naive(stream.data(), stream.size());
  } else if (std::strcmp(mode, "memcpy") == 0) {
    check += bench_memcpy(stream.data(), stream.size());
  } else {
    std::fprintf(stderr, "unknown mode %s\n", mode);
    return 2;
  }
  std::printf("checksum=%u\n", check);
  return 0;
}
