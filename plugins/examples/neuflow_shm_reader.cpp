// neuflow-shm-reader: follows the flow ring a `neuflowshmsink` publishes into and prints one
// line per flow (sequence, frame numbers, timestamps, grid size, mean |flow|), verifying each
// flow's CRC-32. Uses nothing but neuflow/flow_ring.hpp and the standard library.
//
//   neuflow-shm-reader /neuflow-front                      # until interrupted
//   neuflow-shm-reader /neuflow-front --count 100 --check  # exit 1 on any bad checksum
//
// Exit status: 0 done, 1 a checksum failed (--check), 2 usage or ring error, 3 the ring or
// --count flows not seen before --timeout.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "neuflow/flow_ring.hpp"

namespace {

namespace ring = neuflow::ring;
using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

struct Options {
  std::string name;
  std::optional<std::uint64_t> count;
  std::optional<double> timeout_s;
  bool check = false;
  bool quiet = false;
};

void usage(std::FILE *out) {
  std::fputs(
      "usage: neuflow-shm-reader NAME [--count N] [--timeout S] [--check] [--quiet]\n"
      "  NAME         the ring's shared-memory name, as neuflowshmsink's shm-name (e.g. /neuflow-front)\n"
      "  --count N    stop after N flows\n"
      "  --timeout S  stop after S seconds (waiting for the ring included)\n"
      "  --check      exit with status 1 if any flow fails its checksum\n"
      "  --quiet      no line per flow, only the summary\n"
      "Prints one line per flow and a final line: summary read=R missed=M torn=T bad_checksum=B generations=G\n",
      out);
}

std::optional<Options> parse(int argc, char **argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> const char * { return i + 1 < argc ? argv[++i] : nullptr; };
    if (arg == "--help" || arg == "-h") {
      usage(stdout);
      std::exit(0);
    } else if (arg == "--check") {
      o.check = true;
    } else if (arg == "--quiet") {
      o.quiet = true;
    } else if (arg == "--count" || arg == "--timeout") {
      const char *v = value();
      char *end = nullptr;
      if (!v) {
        std::fprintf(stderr, "neuflow-shm-reader: %s needs a value\n", arg.c_str());
        return std::nullopt;
      }
      if (arg == "--count") {
        const unsigned long long n = std::strtoull(v, &end, 10);
        if (*v == '-' || *end || n == 0) {
          std::fprintf(stderr, "neuflow-shm-reader: --count expects a positive integer, got \"%s\"\n", v);
          return std::nullopt;
        }
        o.count = n;
      } else {
        const double s = std::strtod(v, &end);
        if (*end || !(s > 0)) {
          std::fprintf(stderr, "neuflow-shm-reader: --timeout expects positive seconds, got \"%s\"\n", v);
          return std::nullopt;
        }
        o.timeout_s = s;
      }
    } else if (!arg.empty() && arg[0] == '-' && arg != "-") {
      std::fprintf(stderr, "neuflow-shm-reader: unknown option \"%s\"\n", arg.c_str());
      return std::nullopt;
    } else if (o.name.empty()) {
      o.name = arg;
    } else {
      std::fprintf(stderr, "neuflow-shm-reader: one ring name expected, got \"%s\" too\n", arg.c_str());
      return std::nullopt;
    }
  }
  if (o.name.empty()) {
    std::fputs("neuflow-shm-reader: no ring name given\n", stderr);
    return std::nullopt;
  }
  return o;
}

std::string seconds(std::uint64_t ns) {
  if (ns == ring::kNoTimestamp) return "?";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", static_cast<double>(ns) / 1e9);
  return buf;
}

double mean_magnitude(const std::vector<float> &uv, std::size_t values) {
  double sum = 0;
  for (std::size_t i = 0; i + 1 < values; i += 2) {
    sum += std::hypot(static_cast<double>(uv[i]), static_cast<double>(uv[i + 1]));
  }
  return values ? sum / static_cast<double>(values / 2) : 0.0;
}

struct Stats {
  std::uint64_t read = 0, missed = 0, torn = 0, bad_checksum = 0, generations = 0;
};

class Follower {
 public:
  explicit Follower(Options options) : o_(std::move(options)) {}

  int run() {
    if (o_.timeout_s) {
      deadline_ =
          Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(*o_.timeout_s));
    }
    std::optional<ring::FlowRingReader> reader = open();
    // Starts with the newest flow, then follows every one published after it.
    std::uint64_t next = reader ? std::max<std::uint64_t>(reader->published(), 1) : 0;
    while (reader && !done()) {
      if (reader->replaced()) {
        // Flows still in the old segment are read first; then its successor is opened.
        if (next > reader->published()) {
          reader.reset();
          reader = open();
          if (!reader) break;
          next = std::max<std::uint64_t>(reader->published(), 1);
        }
      }
      if (!reader) break;  // the successor did not appear before the deadline
      const std::uint64_t published = reader->published();
      if (next > published) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      // Lapped by the writer: skip what it has already overwritten.
      if (published - next >= reader->slot_count()) {
        const std::uint64_t oldest = published - reader->slot_count() + 1;
        stats_.missed += oldest - next;
        next = oldest;
      }
      uv_.resize(reader->values_per_flow());
      ring::FlowInfo info;
      switch (reader->read(next, uv_, info)) {
        case ring::ReadStatus::ok: report(*reader, info); break;
        case ring::ReadStatus::overwritten: ++stats_.missed; break;
        case ring::ReadStatus::torn: ++stats_.torn; break;
        case ring::ReadStatus::not_published: continue;  // cannot happen for next <= published
      }
      ++next;
    }
    if (error_) return finish(2);
    if (stats_.generations == 0 && !g_stop) {
      std::fprintf(stderr, "neuflow-shm-reader: timed out after %.3g s waiting for the ring\n", *o_.timeout_s);
      return finish(3);
    }
    if (o_.count && stats_.read < *o_.count && !g_stop) {
      std::fprintf(stderr, "neuflow-shm-reader: timed out after %.3g s with %llu of %llu flows\n", *o_.timeout_s,
                   static_cast<unsigned long long>(stats_.read), static_cast<unsigned long long>(*o_.count));
      return finish(3);
    }
    return finish(o_.check && stats_.bad_checksum > 0 ? 1 : 0);
  }

 private:
  bool timed_out() const { return deadline_ && Clock::now() >= *deadline_; }
  bool done() const { return g_stop || timed_out() || (o_.count && stats_.read >= *o_.count); }

  // Opens the ring, waiting while it does not exist yet or is not ready (until the deadline).
  std::optional<ring::FlowRingReader> open() {
    std::string last_wait;
    while (!g_stop && !timed_out()) {
      try {
        ring::FlowRingReader reader(o_.name);
        ++stats_.generations;
        if (!o_.quiet) {
          std::printf("ring %s generation %llu: grid %ux%u, %u slots, writer pid %u\n", o_.name.c_str(),
                      static_cast<unsigned long long>(reader.generation()), reader.width(), reader.height(),
                      reader.slot_count(), reader.writer_pid());
          std::fflush(stdout);
        }
        return reader;
      } catch (const ring::RingError &e) {
        if (!e.retryable()) {
          std::fprintf(stderr, "neuflow-shm-reader: %s\n", e.what());
          error_ = true;
          return std::nullopt;
        }
        if (last_wait != e.what()) {
          std::fprintf(stderr, "neuflow-shm-reader: waiting: %s\n", e.what());
          last_wait = e.what();
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return std::nullopt;
  }

  void report(const ring::FlowRingReader &reader, const ring::FlowInfo &info) {
    ++stats_.read;
    // A flow that passed the seqlock but not its checksum would be a torn read: the
    // failure this reader exists to catch.
    const bool whole =
        info.grid_width == reader.width() && info.grid_height == reader.height() && ring::verify(uv_, info);
    if (!whole) ++stats_.bad_checksum;
    if (o_.quiet && whole) return;
    std::printf(
        "seq=%llu frames=%llu->%llu pts=%s->%s grid=%ux%u frame=%ux%u mean|flow|=%.4f inference=%.1fms crc=%s\n",
        static_cast<unsigned long long>(info.sequence), static_cast<unsigned long long>(info.from_frame),
        static_cast<unsigned long long>(info.to_frame), seconds(info.from_pts_ns).c_str(),
        seconds(info.to_pts_ns).c_str(), info.grid_width, info.grid_height, info.frame_width, info.frame_height,
        mean_magnitude(uv_, reader.values_per_flow()), static_cast<double>(info.inference_ns) / 1e6,
        whole ? "ok" : "MISMATCH");
    std::fflush(stdout);
  }

  int finish(int status) {
    std::printf("summary read=%llu missed=%llu torn=%llu bad_checksum=%llu generations=%llu\n",
                static_cast<unsigned long long>(stats_.read), static_cast<unsigned long long>(stats_.missed),
                static_cast<unsigned long long>(stats_.torn), static_cast<unsigned long long>(stats_.bad_checksum),
                static_cast<unsigned long long>(stats_.generations));
    std::fflush(stdout);
    return status;
  }

  Options o_;
  std::optional<Clock::time_point> deadline_;
  std::vector<float> uv_;
  Stats stats_;
  bool error_ = false;
};

}  // namespace

int main(int argc, char **argv) {
  auto options = parse(argc, argv);
  if (!options) {
    usage(stderr);
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return Follower(std::move(*options)).run();
}
