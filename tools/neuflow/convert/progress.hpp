#pragma once
// Progress of `neuflow convert` on stderr. On a terminal: one line redrawn in place with a
// bar, the rate in pairs per second and the time left. Otherwise (a log, a pipe): a plain
// line every few seconds, so logs stay readable.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <optional>
#include <string>

namespace neuflow::cli {

class Progress {
 public:
  using Clock = std::chrono::steady_clock;

  // `terminal`: redraw one line (use isatty on the stream); `width` is the line's length
  // there. `interval`: time between plain lines.
  Progress(std::FILE* out, bool terminal, int width = 80, Clock::duration interval = std::chrono::seconds(5));

  // Starts counting for one input; `total_pairs` when known.
  void begin(const std::string& label, std::optional<std::int64_t> total_pairs);
  void set_total(std::optional<std::int64_t> total_pairs);
  // One pair done, computed or skipped (--resume); `now` for tests.
  void pair_done(Clock::time_point now = Clock::now());
  // Clears the redrawn line and prints `line` on its own.
  void print(const std::string& line);
  // Clears the input's redrawn line; the summary reports the result.
  void end();

  // Pairs per second over the recent pairs, once there are two.
  std::optional<double> rate() const;
  std::int64_t pairs_done() const { return done_; }

  // Seconds as "4.2 s", "42 s", "3:07" or "1:02:03".
  static std::string format_duration(double seconds);

 private:
  std::string status_text(bool with_bar) const;
  void draw(Clock::time_point now, bool force);

  std::FILE* out_;
  bool terminal_;
  int width_;
  Clock::duration interval_;
  std::string label_;
  std::optional<std::int64_t> total_;
  std::int64_t done_ = 0;
  Clock::time_point started_, last_draw_;
  std::deque<Clock::time_point> recent_;  // when the last pairs finished, for the rate
  bool line_open_ = false;                // a redrawn line is on the terminal
};

}  // namespace neuflow::cli
