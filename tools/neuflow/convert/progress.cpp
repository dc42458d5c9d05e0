#include "convert/progress.hpp"

#include <algorithm>
#include <cmath>

namespace neuflow::cli {

namespace {

// The rate follows the last pairs only: after --resume skipped a run of pairs in no time,
// the time left soon reflects the pairs that are really computed.
constexpr std::size_t kRateWindow = 16;
// A terminal redraw at most this often, so skipping thousands of pairs does not flood it.
constexpr auto kRedrawInterval = std::chrono::milliseconds(100);

}  // namespace

Progress::Progress(std::FILE* out, bool terminal, int width, Clock::duration interval)
    : out_(out), terminal_(terminal), width_(std::max(width, 40)), interval_(interval) {}

std::string Progress::format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  char text[32];
  if (seconds < 9.95) {
    std::snprintf(text, sizeof text, "%.1f s", seconds);
    return text;
  }
  const auto s = static_cast<long long>(std::llround(seconds));
  if (s < 60) {
    std::snprintf(text, sizeof text, "%lld s", s);
  } else if (s < 3600) {
    std::snprintf(text, sizeof text, "%lld:%02lld", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lld:%02lld:%02lld", s / 3600, s / 60 % 60, s % 60);
  }
  return text;
}

void Progress::begin(const std::string& label, std::optional<std::int64_t> total_pairs) {
  label_ = label;
  total_ = total_pairs;
  done_ = 0;
  recent_.clear();
  started_ = last_draw_ = Clock::now();
  recent_.push_back(started_);
}

void Progress::set_total(std::optional<std::int64_t> total_pairs) { total_ = total_pairs; }

std::optional<double> Progress::rate() const {
  if (recent_.size() < 2) return std::nullopt;
  const double seconds = std::chrono::duration<double>(recent_.back() - recent_.front()).count();
  if (seconds <= 0) return std::nullopt;
  return static_cast<double>(recent_.size() - 1) / seconds;
}

std::string Progress::status_text(bool with_bar) const {
  std::string counts = std::to_string(done_);
  if (total_) counts += "/" + std::to_string(*total_);
  counts += " pairs";
  std::string tail;
  if (const auto r = rate()) {
    char text[48];
    std::snprintf(text, sizeof text, ", %.2f pairs/s", *r);
    tail += text;
    if (total_ && *total_ >= done_) tail += ", ETA " + format_duration(static_cast<double>(*total_ - done_) / *r);
  }
  if (!with_bar || !total_ || *total_ <= 0) return label_ + ": " + counts + tail;

  // The bar takes what the line has left after the label and the numbers.
  std::string label = label_;
  const int fixed = static_cast<int>(counts.size() + tail.size()) + 5;
  int bar = width_ - fixed - static_cast<int>(label.size());
  if (bar < 10) {
    const int keep = std::max(8, width_ - fixed - 10);
    if (static_cast<int>(label.size()) > keep)
      label = "..." + label.substr(label.size() - static_cast<std::size_t>(keep - 3));
    bar = std::max(10, width_ - fixed - static_cast<int>(label.size()));
  }
  const double fraction = std::clamp(static_cast<double>(done_) / static_cast<double>(*total_), 0.0, 1.0);
  const int filled = static_cast<int>(fraction * bar);
  return label + " [" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(bar - filled), '-') + "] " + counts + tail;
}

void Progress::draw(Clock::time_point now, bool force) {
  if (terminal_) {
    if (!force && now - last_draw_ < kRedrawInterval) return;
    // \r back to the start, \033[K clears what a longer earlier line left behind.
    std::fprintf(out_, "\r%s\033[K", status_text(true).c_str());
    line_open_ = true;
  } else {
    if (!force && now - last_draw_ < interval_) return;
    std::fprintf(out_, "%s\n", status_text(false).c_str());
  }
  std::fflush(out_);
  last_draw_ = now;
}

void Progress::pair_done(Clock::time_point now) {
  ++done_;
  recent_.push_back(now);
  while (recent_.size() > kRateWindow + 1) recent_.pop_front();
  draw(now, false);
}

void Progress::print(const std::string& line) {
  if (line_open_) std::fputs("\r\033[K", out_);
  line_open_ = false;
  std::fprintf(out_, "%s\n", line.c_str());
  std::fflush(out_);
}

void Progress::end() {
  if (line_open_) std::fputs("\r\033[K", out_);
  line_open_ = false;
  std::fflush(out_);
}

}  // namespace neuflow::cli
