// Virtual drone: the firmware logic against the fake Arduino core, talking
// over a pseudo-terminal (or stdin), reporting its outputs as JSON lines.
//
//   virtual_drone [--clock realtime|stepped] [--stdin] [--duration MS]
//                 [--no-reset-on-open]
//
// pty mode (default): prints {"pty": "/dev/pts/N"} first; the Pi side opens
//   that path. Replies go back over the pty. Opening the port reboots the
//   virtual board (as DTR does a real Uno): it prints its ready line again.
// --clock stepped: stdin carries "step <ms> [<sent>]" lines; each one reads
//   the bytes waiting on the pty (with <sent>, the bytes the client has written
//   since it opened the port: it waits until they all arrived), runs the loop
//   1 ms at a time, prints the change lines and then {"tick": t_ms, "wrote": n},
//   n the bytes written to the pty since it was opened. Nothing depends on the
//   wall clock.
// --stdin: serial input from stdin instead of a pty, replies printed as
//   {"t_ms":..,"tx":"..."}. With --clock stepped, stdin is a script of lines
//   "rx <hex bytes>", "step <ms>" and "stats" (used by the tests).
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/inotify.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <deque>
#include <string>

#include "../drone/drone_app.h"
#include "fake_arduino.h"

namespace {

enum class Clock { Realtime, Stepped };

struct Options {
  Clock clock = Clock::Realtime;
  bool use_stdin = false;
  long duration_ms = -1;
  bool reset_on_open = true;
};

int g_master = -1;
int g_inotify = -1;  // watches the pty's slave node for opens
int g_slave = -1;    // our own slave descriptor, which keeps the port raw
int g_clients = 0;   // descriptors others hold on the slave node
std::deque<uint8_t> g_pending;  // bytes "on the wire", not yet in the UART
uint32_t g_byte_credit = 0;     // receive line, in 1/10000 byte units
uint32_t g_tx_credit = 0;       // transmit line, same units
uint32_t g_t = 0;
// Bytes read from and written to the pty since the last client opened it: the
// barrier of a "step <ms> <sent>" line, and the "wrote" of its tick line.
uint64_t g_rx_total = 0;
uint64_t g_tx_total = 0;
bool g_first = true;
drone::Outputs g_last;
drone::State g_last_state;
bool g_last_armed = false;
Options g_opt;

void json_string(std::string& out, const std::string& s) {
  out += '"';
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c == '\n') {
      out += "\\n";
    } else if (c < 0x20 || c >= 0x7f) {
      char buf[8];
      snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  out += '"';
}

void report_if_changed() {
  const drone::Drone& d = drone_app::logic();
  const drone::Outputs& o = d.outputs();
  if (!g_first && o == g_last && d.state() == g_last_state && d.armed() == g_last_armed) return;
  g_first = false;
  g_last = o;
  g_last_state = d.state();
  g_last_armed = d.armed();
  printf(
      "{\"t_ms\":%u,\"roll\":%u,\"pitch\":%u,\"throttle\":%u,\"yaw\":%u,\"mode\":%u,\"pan\":%u,\"tilt\":%u,"
      "\"laser\":%s,\"armed\":%s,\"state\":\"%s\"}\n",
      g_t, o.roll, o.pitch, o.throttle, o.yaw, o.mode, o.pan, o.tilt, o.laser ? "true" : "false",
      d.armed() ? "true" : "false", drone::state_name(d.state()));
}

// The UART sends what the baud rate allows in this millisecond.
void send_replies() {
  g_tx_credit += drone::dp::BAUD;
  const std::string tx = fake::tx_take(g_tx_credit / 10000);
  g_tx_credit -= static_cast<uint32_t>(tx.size()) * 10000;
  if (g_tx_credit > 20000) g_tx_credit = 20000;
  if (tx.empty()) return;
  if (g_opt.use_stdin) {
    // One JSON record per complete reply line, stamped when its '\n' left.
    static std::string partial;
    partial += tx;
    size_t nl;
    while ((nl = partial.find('\n')) != std::string::npos) {
      std::string line = "{\"t_ms\":" + std::to_string(g_t) + ",\"tx\":";
      json_string(line, partial.substr(0, nl + 1));
      line += "}\n";
      fputs(line.c_str(), stdout);
      partial.erase(0, nl + 1);
    }
  } else if (g_master >= 0 && (g_inotify < 0 || g_clients > 0)) {
    // Non-blocking: with nobody reading, replies are lost, as on a real UART.
    const ssize_t r = write(g_master, tx.data(), tx.size());
    if (r > 0) g_tx_total += static_cast<uint64_t>(r);
  }
}

// One millisecond of firmware time: the wire delivers what 1 ms of the baud
// rate carries, then the sketch's loop() runs.
void run_one_ms() {
  ++g_t;
  fake::set_millis(g_t);
  g_byte_credit += drone::dp::BAUD;  // bytes/ms = BAUD / 10 bits / 1000
  while (!g_pending.empty() && g_byte_credit >= 10000 && fake::rx_space() > 0) {
    const uint8_t b = g_pending.front();
    g_pending.pop_front();
    fake::rx_push(&b, 1);
    g_byte_credit -= 10000;
  }
  if (g_pending.empty() && g_byte_credit > 20000) g_byte_credit = 20000;
  drone_app::loop();
  send_replies();
  report_if_changed();
}

// A client opened the port: reboot the firmware (state, buffers, ready line).
void reset_if_opened() {
  if (g_inotify < 0) return;
  alignas(inotify_event) char buf[4096];
  bool opened = false;
  for (;;) {
    const ssize_t n = read(g_inotify, buf, sizeof buf);
    if (n <= 0) break;
    for (ssize_t i = 0; i < n;) {
      const inotify_event* e = reinterpret_cast<const inotify_event*>(buf + i);
      if (e->mask & IN_OPEN) {
        ++g_clients;
        opened = true;
      }
      if ((e->mask & (IN_CLOSE_WRITE | IN_CLOSE_NOWRITE)) && g_clients > 0) --g_clients;
      i += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
    }
  }
  if (!opened) return;
  // What the old "board" sent before the port opened is gone, as on a USB
  // serial port that was closed.
  if (g_slave >= 0) tcflush(g_slave, TCIFLUSH);
  g_pending.clear();
  g_rx_total = g_tx_total = 0;
  fake::reset_serial();
  drone_app::setup();
  send_replies();
  report_if_changed();
}

void read_master() {
  reset_if_opened();
  if (g_master < 0) return;
  uint8_t buf[256];
  for (;;) {
    const ssize_t n = read(g_master, buf, sizeof buf);
    if (n <= 0) break;  // EAGAIN, or EIO while no client has the port open
    g_pending.insert(g_pending.end(), buf, buf + n);
    g_rx_total += static_cast<uint64_t>(n);
  }
}

// Before a step: bytes a client wrote just before its "step" line may still
// be on their way through the kernel's pty buffer (pushed by a work queue).
// Give them a moment, so a frame written before a step lands in that step.
void settle_master() {
  if (g_master < 0 || (g_inotify >= 0 && g_clients == 0)) return;
  pollfd p;
  p.fd = g_master;
  p.events = POLLIN;
  if (poll(&p, 1, 0) > 0) return;
  const timespec pause = {0, 200 * 1000};  // 0.2 ms of wall time per quiet step
  nanosleep(&pause, nullptr);
}

// A step that names how many bytes the client has written since it opened the
// port waits (up to 2 s of wall time) until they all came through the kernel's
// pty buffer: on a loaded machine its work queue can hold them longer than
// any fixed pause, and a frame would land a step late.
void await_master(uint64_t sent) {
  for (int waited_ms = 0; waited_ms < 2000; ++waited_ms) {
    read_master();
    if (g_rx_total >= sent) return;
    pollfd p;
    p.fd = g_master;
    p.events = POLLIN;
    poll(&p, 1, 1);
  }
  fprintf(stderr, "virtual_drone: %llu of %llu bytes arrived\n", static_cast<unsigned long long>(g_rx_total),
          static_cast<unsigned long long>(sent));
}

int open_pty() {
  const int m = posix_openpt(O_RDWR | O_NOCTTY);
  if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0) {
    perror("pty");
    exit(1);
  }
  const char* name = ptsname(m);
  // Keep a slave descriptor open ourselves: the master then never sees a
  // hang-up between clients, and the port is raw from the start (no echo).
  const int s = open(name, O_RDWR | O_NOCTTY);
  g_slave = s;
  if (s >= 0) {
    termios tio;
    tcgetattr(s, &tio);
    cfmakeraw(&tio);
    tcsetattr(s, TCSANOW, &tio);
  }
  fcntl(m, F_SETFL, fcntl(m, F_GETFL) | O_NONBLOCK);
  // Opening a real Uno's port pulses DTR and resets the board; the Pi waits
  // for the ready line. A client opening the slave node does the same here.
  if (g_opt.reset_on_open) {
    g_inotify = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (g_inotify >= 0 && inotify_add_watch(g_inotify, name, IN_OPEN | IN_CLOSE_WRITE | IN_CLOSE_NOWRITE) < 0) {
      close(g_inotify);
      g_inotify = -1;
    }
  }
  printf("{\"pty\": \"%s\"}\n", name);
  fflush(stdout);
  return m;
}

uint64_t wall_ms() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000u + static_cast<uint64_t>(ts.tv_nsec) / 1000000u;
}

// Counters the JSON change lines do not carry: dropped replies and parser
// errors per kind.
void print_stats() {
  const drone::Drone& d = drone_app::logic();
  printf("{\"t_ms\":%u,\"replies_dropped\":%u,\"errors\":{", g_t, d.replies_dropped());
  for (uint8_t i = 1; i <= drone::dp::PARSER_ERROR_COUNT; ++i) {
    const drone::dp::Error e = static_cast<drone::dp::Error>(i);
    printf("%s\"%s\":%u", i > 1 ? "," : "", drone::dp::error_name(e), d.parser().error_count(e));
  }
  printf("}}\n");
}

bool parse_hex(const char* s, std::deque<uint8_t>& out) {
  while (*s == ' ') ++s;
  while (s[0] && s[0] != '\n') {
    char hex[3] = {s[0], s[1], 0};
    char* end = nullptr;
    const long v = strtol(hex, &end, 16);
    if (end != hex + 2) return false;
    out.push_back(static_cast<uint8_t>(v));
    s += 2;
  }
  return true;
}

int run_stepped() {
  char line[4096];
  while (fgets(line, sizeof line, stdin)) {
    if (strncmp(line, "step", 4) == 0) {
      char* rest = nullptr;
      const long ms = strtol(line + 4, &rest, 10);
      char* after = nullptr;
      const long long sent = strtoll(rest, &after, 10);
      reset_if_opened();
      if (after != rest && g_master >= 0) {
        await_master(static_cast<unsigned long long>(sent));
      } else {
        settle_master();
        read_master();
      }
      for (long i = 0; i < ms; ++i) run_one_ms();
      printf("{\"tick\":%u,\"wrote\":%llu}\n", g_t, static_cast<unsigned long long>(g_tx_total));
      fflush(stdout);
    } else if (g_opt.use_stdin && strncmp(line, "rx", 2) == 0) {
      if (!parse_hex(line + 2, g_pending)) {
        fprintf(stderr, "bad hex: %s", line);
        return 2;
      }
    } else if (g_opt.use_stdin && strncmp(line, "stats", 5) == 0) {
      print_stats();
    } else if (strncmp(line, "quit", 4) == 0) {
      break;
    } else if (line[0] != '\n' && line[0] != '#') {
      fprintf(stderr, "unknown command: %s", line);
      return 2;
    }
  }
  return 0;
}

int run_realtime() {
  const uint64_t start = wall_ms();
  bool stdin_open = g_opt.use_stdin;
  for (;;) {
    pollfd fds[1];
    fds[0].fd = g_opt.use_stdin ? (stdin_open ? 0 : -1) : g_master;
    fds[0].events = POLLIN;
    poll(fds, 1, 1);
    if (g_opt.use_stdin && stdin_open && (fds[0].revents & (POLLIN | POLLHUP))) {
      uint8_t buf[256];
      const ssize_t n = read(0, buf, sizeof buf);
      if (n <= 0) {
        stdin_open = false;
      } else {
        g_pending.insert(g_pending.end(), buf, buf + n);
      }
    } else if (!g_opt.use_stdin) {
      read_master();
    }
    const uint64_t now = wall_ms() - start;
    while (g_t < now) run_one_ms();
    fflush(stdout);
    if (g_opt.duration_ms >= 0 && g_t >= g_opt.duration_ms) break;
    // --stdin without a duration: stop once the input is used up.
    if (g_opt.use_stdin && !stdin_open && g_opt.duration_ms < 0 && g_pending.empty()) break;
  }
  return 0;
}

void usage() {
  fputs("usage: virtual_drone [--clock realtime|stepped] [--stdin] [--duration MS] [--no-reset-on-open]\n", stderr);
  exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--clock" && i + 1 < argc) {
      const std::string c = argv[++i];
      if (c == "realtime") {
        g_opt.clock = Clock::Realtime;
      } else if (c == "stepped") {
        g_opt.clock = Clock::Stepped;
      } else {
        usage();
      }
    } else if (a == "--no-reset-on-open") {
      g_opt.reset_on_open = false;
    } else if (a == "--stdin") {
      g_opt.use_stdin = true;
    } else if (a == "--duration" && i + 1 < argc) {
      g_opt.duration_ms = strtol(argv[++i], nullptr, 10);
    } else {
      usage();
    }
  }
  setvbuf(stdout, nullptr, _IOLBF, 0);
  if (!g_opt.use_stdin) g_master = open_pty();
  fake::set_millis(0);
  drone_app::setup();
  send_replies();
  report_if_changed();
  return g_opt.clock == Clock::Stepped ? run_stepped() : run_realtime();
}
