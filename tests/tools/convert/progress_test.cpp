#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "convert/progress.hpp"

namespace neuflow::cli {
namespace {

// What the progress wrote into a temporary FILE*.
class Captured {
 public:
  Captured() : file_(std::tmpfile()) {}
  ~Captured() { std::fclose(file_); }
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    std::rewind(file_);
    std::string s;
    for (int c; (c = std::fgetc(file_)) != EOF;) s += static_cast<char>(c);
    return s;
  }

 private:
  std::FILE* file_;
};

using std::chrono::milliseconds;
using std::chrono::seconds;

TEST(Progress, PlainLinesOnlyEveryInterval) {
  Captured out;
  Progress progress(out.file(), false, 80, seconds(5));
  progress.begin("clip.mp4", 10);
  const auto t0 = Progress::Clock::now();
  progress.pair_done(t0 + seconds(1));
  progress.pair_done(t0 + seconds(2));
  EXPECT_EQ(out.text(), "");  // nothing before the interval has passed
  progress.pair_done(t0 + seconds(6));
  const std::string text = out.text();
  EXPECT_NE(text.find("clip.mp4: 3/10 pairs"), std::string::npos) << text;
  EXPECT_NE(text.find("pairs/s"), std::string::npos) << text;
  EXPECT_NE(text.find("ETA"), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << "no terminal control characters in a log";
  EXPECT_EQ(text.back(), '\n');
}

TEST(Progress, RateFollowsRecentPairs) {
  Captured out;
  Progress progress(out.file(), false, 80, seconds(1000));
  progress.begin("frames", 100);
  const auto t0 = Progress::Clock::now();
  EXPECT_FALSE(progress.rate());
  // Fifty pairs skipped in no time, then pairs every 2 s: the rate settles at 0.5/s.
  for (int i = 0; i < 50; ++i) progress.pair_done(t0 + milliseconds(i));
  for (int i = 1; i <= 20; ++i) progress.pair_done(t0 + seconds(2 * i));
  ASSERT_TRUE(progress.rate());
  EXPECT_NEAR(*progress.rate(), 0.5, 1e-9);
  EXPECT_EQ(progress.pairs_done(), 70);
}

TEST(Progress, TerminalRedrawsOneLineWithABar) {
  Captured out;
  Progress progress(out.file(), true, 60);
  progress.begin("frames", 4);
  const auto t0 = Progress::Clock::now();
  progress.pair_done(t0 + seconds(1));
  progress.pair_done(t0 + seconds(2));
  std::string text = out.text();
  EXPECT_EQ(text.find('\n'), std::string::npos) << "the line is redrawn, not repeated";
  const auto last = text.substr(text.rfind('\r'));
  EXPECT_NE(last.find("[##"), std::string::npos) << last;
  EXPECT_NE(last.find("2/4 pairs"), std::string::npos) << last;
  EXPECT_NE(last.find("ETA 2.0 s"), std::string::npos) << last;  // one pair a second, two left
  progress.print("frames: FAILED: something");
  progress.end();
  text = out.text();
  EXPECT_NE(text.find("\r\033[Kframes: FAILED: something\n"), std::string::npos);
}

TEST(Progress, UnknownTotalHasNoBarNorEta) {
  Captured out;
  Progress progress(out.file(), true, 80);
  progress.begin("rtsp://camera", std::nullopt);
  const auto t0 = Progress::Clock::now();
  progress.pair_done(t0 + seconds(1));
  progress.pair_done(t0 + seconds(2));
  const std::string text = out.text();
  EXPECT_NE(text.find("2 pairs"), std::string::npos) << text;
  EXPECT_EQ(text.find("ETA"), std::string::npos) << text;
  EXPECT_EQ(text.find("[#"), std::string::npos) << text;
  EXPECT_EQ(text.find("[-"), std::string::npos) << text;
}

TEST(Progress, FormatsDurations) {
  EXPECT_EQ(Progress::format_duration(4.44), "4.4 s");
  EXPECT_EQ(Progress::format_duration(42.4), "42 s");
  EXPECT_EQ(Progress::format_duration(187), "3:07");
  EXPECT_EQ(Progress::format_duration(3723), "1:02:03");
  EXPECT_EQ(Progress::format_duration(-1), "?");
}

}  // namespace
}  // namespace neuflow::cli
