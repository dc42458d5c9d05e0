// `neuflow convert` end to end: the real binary on frames from the fixture camera sequence
// (downscaled at test time) and on videos made with GStreamer, checked against the model
// run in this process.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/exit_codes.hpp"
#include "convert/frames.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/pipeline/video_decoder.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"
#include "test_media.hpp"

namespace neuflow::cli {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

constexpr int kWidth = 64, kHeight = 48;

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

RunResult run_neuflow(const std::vector<std::string>& args) {
  std::string command = shell_quote(NEUFLOW_BIN);
  for (const auto& a : args) command += " " + shell_quote(a);
  command += " 2>&1";
  RunResult result;
  std::FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) result.output.append(buffer, n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

std::vector<std::vector<std::string>> read_csv(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string field; std::getline(ss, field, ',');) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.emplace_back();
    rows.push_back(fields);
  }
  return rows;
}

double max_difference(const flow::FlowField& a, const flow::FlowField& b) {
  if (a.width != b.width || a.height != b.height) return INFINITY;
  double worst = 0;
  for (std::size_t i = 0; i < a.uv.size(); ++i)
    worst = std::max(worst, static_cast<double>(std::abs(a.uv[i] - b.uv[i])));
  return worst;
}

class ConvertCli : public ::testing::Test {
 protected:
  void SetUp() override {
    NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
    NEUFLOW_REQUIRE_FIXTURE(frames, "frames");
    checkpoint_ = checkpoint;
    for (const auto& entry : fs::directory_iterator(frames)) {
      if (entry.path().extension() == ".jpg") camera_frames_.push_back(entry.path());
    }
    std::sort(camera_frames_.begin(), camera_frames_.end());
    ASSERT_GE(camera_frames_.size(), 5u);
  }

  // The first camera frames, downscaled, saved under `names` in `folder`.
  std::vector<cv::Mat> make_frames(const fs::path& folder, const std::vector<std::string>& names, int width = kWidth,
                                   int height = kHeight) {
    fs::create_directories(folder);
    std::vector<cv::Mat> images;
    for (std::size_t i = 0; i < names.size(); ++i) {
      const cv::Mat full = cv::imread(camera_frames_.at(i).string(), cv::IMREAD_COLOR);
      cv::Mat small;
      cv::resize(full, small, cv::Size(width, height), 0, 0, cv::INTER_AREA);
      EXPECT_TRUE(cv::imwrite((folder / names[i]).string(), small));
      images.push_back(small);
    }
    return images;
  }

  std::vector<std::string> convert_args(const fs::path& output) const {
    return {"convert", "-m", checkpoint_.string(), "--iters-s16", "1", "--iters-s8", "1", "--threads",
            "1",       "-o", output.string()};
  }

  RunResult convert(const fs::path& output, const std::vector<std::string>& more) const {
    auto args = convert_args(output);
    args.insert(args.end(), more.begin(), more.end());
    return run_neuflow(args);
  }

  // The flow the library computes for one pair, with the options convert_args gives.
  flow::FlowField reference_flow(const cv::Mat& a, const cv::Mat& b) const {
    static const auto model = model::FlowModel::load(checkpoint_);
    model::SessionOptions options;
    options.iterations = {1, 1};
    options.threads = 1;
    model::FlowSession session(model, options);
    const auto view = [](const cv::Mat& m) {
      return model::ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), model::ChannelOrder::bgr};
    };
    return session.compute(view(a), view(b));
  }

  fs::path checkpoint_;
  std::vector<fs::path> camera_frames_;
};

TEST_F(ConvertCli, FolderInNaturalOrderGivesOneFlowPerPairEqualToThePairwiseResult) {
  TempDir dir;
  // Plain string order would be frame1, frame10, frame11, frame2, frame3.
  const std::vector<std::string> names = {"frame1.png", "frame2.png", "frame3.png", "frame10.png", "frame11.png"};
  const auto images = make_frames(dir / "seq", names);
  const auto result = convert(dir / "out", {(dir / "seq").string()});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("1 input, 1 converted, 0 failed"), std::string::npos) << result.output;

  const fs::path out = dir / "out" / "seq";
  const auto index = read_csv(out / "index.csv");
  ASSERT_EQ(index.size(), 5u) << "header + 4 pairs";
  EXPECT_EQ(index[0], (std::vector<std::string>{"index", "from_frame", "to_frame", "from_pts_ns", "to_pts_ns", "file",
                                                "from_source", "to_source"}));
  for (std::size_t i = 0; i + 1 < names.size(); ++i) {
    const std::string stem = fs::path(names[i]).stem().string();
    EXPECT_EQ(index[i + 1], (std::vector<std::string>{std::to_string(i), std::to_string(i), std::to_string(i + 1), "",
                                                      "", stem + ".flo", names[i], names[i + 1]}));
    const auto written = flow::read_flow(out / (stem + ".flo"));
    EXPECT_EQ(written.width, kWidth);
    EXPECT_EQ(written.height, kHeight);
    // Streaming (backbone reused from the previous pair) gives the pairwise result.
    EXPECT_LT(max_difference(written, reference_flow(images[i], images[i + 1])), 1e-4) << stem;
  }
  EXPECT_EQ(test::hidden_files(out), "");
}

TEST_F(ConvertCli, VideoGivesFlowsAndAnMp4ThatDecodes) {
  TempDir dir;
  const auto video = test::make_test_video(dir / "ball.mp4", 6, kWidth, kHeight);
  const auto result = convert(dir / "out", {video.string(), "--viz", "video"});
  ASSERT_EQ(result.exit_code, 0) << result.output;

  const fs::path out = dir / "out" / "ball";
  const auto index = read_csv(out / "index.csv");
  ASSERT_EQ(index.size(), 6u) << "header + 5 pairs";
  for (int i = 0; i < 5; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d.flo", i);
    const auto& row = index[static_cast<std::size_t>(i) + 1];
    ASSERT_EQ(row.size(), 8u);
    EXPECT_EQ(row[1], std::to_string(i));
    EXPECT_EQ(row[2], std::to_string(i + 1));
    EXPECT_NEAR(std::stod(row[4]) - std::stod(row[3]), 100e6, 1e6);  // 10 fps
    if (i > 0) {
      EXPECT_EQ(row[3], index[static_cast<std::size_t>(i)][4]) << "consecutive pairs share a frame";
    }
    EXPECT_EQ(row[5], name);
    const auto field = flow::read_flow(out / name);
    EXPECT_EQ(field.width, kWidth);
    EXPECT_EQ(field.height, kHeight);
  }

  pipeline::VideoDecoder decoder((out / "viz.mp4").string());
  int frames = 0;
  while (auto frame = decoder.next()) {
    EXPECT_EQ(frame->width, kWidth);
    EXPECT_EQ(frame->height, kHeight);
    ++frames;
  }
  EXPECT_EQ(frames, 5);
  EXPECT_EQ(decoder.frame_rate().numerator, 10);
  EXPECT_EQ(test::hidden_files(out), "");
}

TEST_F(ConvertCli, MaxFramesLimitsEachInput) {
  TempDir dir;
  const auto video = test::make_test_video(dir / "ball.mp4", 6, kWidth, kHeight);
  make_frames(dir / "seq", {"a.png", "b.png", "c.png", "d.png"});
  const auto result = convert(dir / "out", {video.string(), (dir / "seq").string(), "--max-frames", "3"});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(read_csv(dir / "out" / "ball" / "index.csv").size(), 3u);
  EXPECT_EQ(read_csv(dir / "out" / "seq" / "index.csv").size(), 3u);
  EXPECT_FALSE(fs::exists(dir / "out" / "ball" / "frame_000002.flo"));
  EXPECT_FALSE(fs::exists(dir / "out" / "seq" / "c.flo"));
}

TEST_F(ConvertCli, ResumeRecomputesOnlyMissingOrIncompleteFlows) {
  TempDir dir;
  make_frames(dir / "seq", {"f1.png", "f2.png", "f3.png", "f4.png", "f5.png"});
  const fs::path out = dir / "out" / "seq";
  const auto full = convert(dir / "out", {(dir / "seq").string(), "--format", "npy"});
  ASSERT_EQ(full.exit_code, 0) << full.output;
  std::vector<flow::FlowField> original;
  for (const char* stem : {"f1", "f2", "f3", "f4"})
    original.push_back(flow::read_flow(out / (std::string(stem) + ".npy")));

  fs::remove(out / "f2.npy");
  fs::resize_file(out / "f3.npy", fs::file_size(out / "f3.npy") / 2);  // an interrupted write
  const auto kept_time = fs::last_write_time(out / "f4.npy");
  const auto resumed = convert(dir / "out", {(dir / "seq").string(), "--format", "npy", "--resume"});
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("4 pairs (2 written, 2 skipped)"), std::string::npos) << resumed.output;
  EXPECT_EQ(fs::last_write_time(out / "f4.npy"), kept_time) << "a complete flow was rewritten";
  const char* stems[] = {"f1", "f2", "f3", "f4"};
  for (int i = 0; i < 4; ++i) {
    // f2 follows the kept f1, so the session restarts there; the result must not change.
    EXPECT_LT(
        max_difference(flow::read_flow(out / (std::string(stems[i]) + ".npy")), original[static_cast<std::size_t>(i)]),
        1e-5)
        << stems[i];
  }
  EXPECT_EQ(read_csv(out / "index.csv").size(), 5u) << "the index lists kept pairs too";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Flows fed RGB are not resumed feeding BGR: the folder is refused (64), naming the difference,
// its flows untouched; --overwrite recomputes them and records the new settings.
TEST_F(ConvertCli, ResumeWithOtherSettingsIsRefusedNamingThemUnlessOverwrite) {
  TempDir dir;
  make_frames(dir / "seq", {"f1.png", "f2.png", "f3.png"});
  const fs::path out = dir / "out" / "seq";
  ASSERT_EQ(convert(dir / "out", {(dir / "seq").string()}).exit_code, 0);
  const std::string record = read_text(out / "settings.toml");
  EXPECT_NE(record.find("iters_s8 = 1"), std::string::npos) << record;
  EXPECT_NE(record.find("format = 'flo'"), std::string::npos) << record;
  EXPECT_NE(record.find("backend = 'cpu'"), std::string::npos) << record;
  const auto sha = record.find("model_sha1 = '");
  ASSERT_NE(sha, std::string::npos) << record;
  EXPECT_EQ(record.find('\'', sha + 14), sha + 14 + 40) << "a git blob SHA-1: " << record;
  const auto kept_time = fs::last_write_time(out / "f1.flo");

  auto args = std::vector<std::string>{(dir / "seq").string(), "--resume", "--channel-order", "bgr"};
  const auto refused = convert(dir / "out", args);
  EXPECT_EQ(refused.exit_code, kExitUsage) << refused.output;
  EXPECT_NE(refused.output.find("--channel-order rgb (now bgr)"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("--overwrite"), std::string::npos) << refused.output;
  EXPECT_EQ(fs::last_write_time(out / "f1.flo"), kept_time) << "a refused folder was written to";
  EXPECT_EQ(read_text(out / "settings.toml"), record);

  args.emplace_back("--overwrite");
  const auto recomputed = convert(dir / "out", args);
  ASSERT_EQ(recomputed.exit_code, 0) << recomputed.output;
  EXPECT_NE(recomputed.output.find("2 pairs (2 written, 0 skipped)"), std::string::npos) << recomputed.output;
  EXPECT_NE(read_text(out / "settings.toml").find("channel_order = 'bgr'"), std::string::npos);

  // The same settings again: resumed.
  args.pop_back();
  const auto resumed = convert(dir / "out", args);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("2 pairs (0 written, 2 skipped)"), std::string::npos) << resumed.output;
}

// A record from before --padding existed holds centred padding: it resumes with the default and
// refuses --padding bottom, naming it.
TEST_F(ConvertCli, ARecordWithoutPaddingMeansCentred) {
  TempDir dir;
  make_frames(dir / "seq", {"f1.png", "f2.png"});
  const fs::path record = dir / "out" / "seq" / "settings.toml";
  ASSERT_EQ(convert(dir / "out", {(dir / "seq").string()}).exit_code, 0);
  std::string text = read_text(record);
  const auto line = text.find("padding = 'centred'");
  ASSERT_NE(line, std::string::npos) << text;
  text.erase(line, text.find('\n', line) + 1 - line);
  std::ofstream(record) << text;
  const auto resumed = convert(dir / "out", {(dir / "seq").string(), "--resume"});
  EXPECT_EQ(resumed.exit_code, 0) << resumed.output;
  const auto refused = convert(dir / "out", {(dir / "seq").string(), "--resume", "--padding", "bottom"});
  EXPECT_EQ(refused.exit_code, kExitUsage) << refused.output;
  EXPECT_NE(refused.output.find("--padding centred (now bottom)"), std::string::npos) << refused.output;
}

TEST_F(ConvertCli, AFolderRecordThatIsNotOneIsNamed) {
  TempDir dir;
  make_frames(dir / "seq", {"f1.png", "f2.png"});
  ASSERT_EQ(convert(dir / "out", {(dir / "seq").string()}).exit_code, 0);
  std::ofstream(dir / "out" / "seq" / "settings.toml") << "iters_s8 = [\n";
  const auto result = convert(dir / "out", {(dir / "seq").string(), "--resume"});
  EXPECT_EQ(result.exit_code, kExitDataError) << result.output;
  EXPECT_NE(result.output.find("settings.toml"), std::string::npos) << result.output;
  EXPECT_EQ(convert(dir / "out", {(dir / "seq").string(), "--resume", "--overwrite"}).exit_code, 0);
}

// A process that has ended: its id names no running process.
pid_t ended_process() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

// Ctrl-C: the run stops after its current pair with 130, saying how to go on; the index lists
// every flow written, no partial file is left, and --resume removes what an earlier killed run
// left and finishes the rest.
TEST_F(ConvertCli, InterruptedRunLeavesACompleteIndexAndResumes) {
  TempDir dir;
  std::vector<std::string> names;
  for (int i = 0; i < 40; ++i) {
    names.push_back(std::to_string(100 + i) + ".png");
    make_frames(dir / "seq", {names.back()}, 160, 96);  // the first camera frame, 40 times
  }
  const fs::path out = dir / "out" / "seq", log = dir / "log.txt";
  auto args = convert_args(dir / "out");
  args.insert(args.end(), {(dir / "seq").string(), "--viz", "video"});
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(NEUFLOW_BIN)};
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::FILE* f = std::freopen(log.c_str(), "w", stderr);
    if (f) ::dup2(::fileno(stderr), STDOUT_FILENO);
    ::execv(NEUFLOW_BIN, argv.data());
    ::_exit(127);
  }
  const auto started = std::chrono::steady_clock::now();
  while (!fs::exists(out / "100.flo") && std::chrono::steady_clock::now() - started < std::chrono::seconds(120)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string said = read_text(log);
  ASSERT_TRUE(WIFEXITED(status)) << said;
  EXPECT_EQ(WEXITSTATUS(status), 130) << said;
  EXPECT_NE(said.find("interrupted: "), std::string::npos) << said;
  EXPECT_NE(said.find(" of 39 pairs of "), std::string::npos) << said;
  EXPECT_NE(said.find("run again with --resume"), std::string::npos) << said;
  std::size_t flows = 0;
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    flows += entry.path().extension() == ".flo";
    EXPECT_EQ(name.find(".partial-"), std::string::npos) << name << " left behind";
    EXPECT_NE(name, "viz.mp4") << "the video of an interrupted run";
  }
  EXPECT_GT(flows, 0u);
  EXPECT_LT(flows, 39u) << "the run ended before it was interrupted";
  EXPECT_EQ(read_csv(out / "index.csv").size(), flows + 1) << "the index lists each flow written";

  const fs::path stale = out / (".viz.mp4.partial-" + std::to_string(ended_process()) + "-0");
  std::ofstream(stale) << "left by a killed run";
  args.emplace_back("--resume");
  const auto resumed = run_neuflow(args);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("39 pairs (" + std::to_string(39 - flows) + " written, " + std::to_string(flows) +
                                " skipped)"),
            std::string::npos)
      << resumed.output;
  EXPECT_FALSE(fs::exists(stale)) << "--resume left an ended run's partial video";
  EXPECT_TRUE(fs::exists(out / "viz.mp4"));
}

TEST_F(ConvertCli, ResumeRebuildsTheVideoFromKeptFlows) {
  TempDir dir;
  make_frames(dir / "seq", {"f1.png", "f2.png", "f3.png", "f4.png"});
  const auto args = std::vector<std::string>{(dir / "seq").string(), "--viz", "video", "--resume"};
  ASSERT_EQ(convert(dir / "out", args).exit_code, 0);
  fs::remove(dir / "out" / "seq" / "viz.mp4");
  const auto resumed = convert(dir / "out", args);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("3 pairs (0 written, 3 skipped)"), std::string::npos) << resumed.output;
  pipeline::VideoDecoder decoder((dir / "out" / "seq" / "viz.mp4").string());
  int frames = 0;
  while (decoder.next()) ++frames;
  EXPECT_EQ(frames, 3);
}

TEST_F(ConvertCli, UnwritableOutputFailsWithCantCreate) {
  TempDir dir;
  make_frames(dir / "seq", {"a.png", "b.png"});
  std::ofstream(dir / "file") << "in the way";
  const auto result = convert(dir / "file", {(dir / "seq").string()});
  EXPECT_EQ(result.exit_code, 73) << result.output;
  EXPECT_NE(result.output.find("seq: FAILED: " + (dir / "file").string()), std::string::npos) << result.output;
}

TEST_F(ConvertCli, BadInputsFailAloneAndAreNamed) {
  TempDir dir;
  make_frames(dir / "good", {"a.png", "b.png", "c.png"});
  make_frames(dir / "mixed", {"a.png", "b.png"});
  make_frames(dir / "mixed_extra", {"c.png"}, 80, 64);
  fs::rename(dir / "mixed_extra" / "c.png", dir / "mixed" / "c.png");
  std::ofstream(dir / "notes.mp4") << "not a video\n";
  const auto video = test::make_test_video(dir / "ball.mp4", 3, kWidth, kHeight);

  const auto result = convert(dir / "out", {(dir / "missing.mp4").string(), (dir / "good").string(),
                                            (dir / "notes.mp4").string(), (dir / "mixed").string(), video.string()});
  EXPECT_EQ(result.exit_code, 66) << "the first failure is the missing file\n" << result.output;
  EXPECT_NE(result.output.find("5 inputs, 2 converted, 3 failed"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find((dir / "missing.mp4").string() + ": FAILED: no such file"), std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find((dir / "notes.mp4").string() + ": FAILED: "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("c.png is 80x64 but b.png is 64x48"), std::string::npos) << result.output;

  EXPECT_EQ(read_csv(dir / "out" / "good" / "index.csv").size(), 3u);
  EXPECT_EQ(read_csv(dir / "out" / "ball" / "index.csv").size(), 3u);
  // The pair before the odd frame was converted and is in the index.
  EXPECT_TRUE(fs::exists(dir / "out" / "mixed" / "a.flo"));
  EXPECT_EQ(read_csv(dir / "out" / "mixed" / "index.csv").size(), 2u);
}

TEST_F(ConvertCli, UndecodableVideoAloneExitsWithDataError) {
  TempDir dir;
  std::ofstream(dir / "notes.mp4") << "not a video\n";
  const auto result = convert(dir / "out", {(dir / "notes.mp4").string()});
  EXPECT_EQ(result.exit_code, 65) << result.output;
}

TEST_F(ConvertCli, ImagePairAsTwoFilesOrWithPair) {
  TempDir dir;
  const auto images = make_frames(dir.path(), {"left.png", "right.png"});
  const auto result = convert(dir / "out", {(dir / "left.png").string(), (dir / "right.png").string(), "--pair",
                                            (dir / "right.png").string(), (dir / "left.png").string()});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto forward = flow::read_flow(dir / "out" / "left_right" / "flow.flo");
  const auto backward = flow::read_flow(dir / "out" / "right_left" / "flow.flo");
  EXPECT_LT(max_difference(forward, reference_flow(images[0], images[1])), 1e-4);
  EXPECT_LT(max_difference(backward, reference_flow(images[1], images[0])), 1e-4);
  const auto index = read_csv(dir / "out" / "left_right" / "index.csv");
  ASSERT_EQ(index.size(), 2u);
  EXPECT_EQ(index[1][5], "flow.flo");
  EXPECT_EQ(index[1][6], "left.png");
  EXPECT_EQ(index[1][7], "right.png");
}

// A pair's KITTI flow is not named like the image it starts from (left.png beside left.png's
// rendering would pass for a copy of the image).
TEST_F(ConvertCli, APairsKittiFlowIsNotNamedAfterItsImage) {
  TempDir dir;
  make_frames(dir.path(), {"left.png", "right.png"});
  const auto result = convert(dir / "out", {"--pair", (dir / "left.png").string(), (dir / "right.png").string(),
                                            "--format", "png", "--viz", "png"});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const fs::path folder = dir / "out" / "left_right";
  EXPECT_TRUE(flow::read_flow(folder / "flow.png").has_mask());
  EXPECT_TRUE(fs::exists(folder / "viz" / "flow.png"));
  EXPECT_FALSE(fs::exists(folder / "left.png"));
  EXPECT_FALSE(fs::exists(folder / "viz" / "left.png"));
}

TEST_F(ConvertCli, KittiFlowsAndPngRenderings) {
  TempDir dir;
  make_frames(dir / "seq", {"a.png", "b.png", "c.png"});
  const auto result = convert(dir / "out", {(dir / "seq").string(), "--format", "png", "--viz", "png"});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const char* stem : {"a", "b"}) {
    const auto field = flow::read_flow(dir / "out" / "seq" / (std::string(stem) + ".png"));
    EXPECT_TRUE(field.has_mask()) << "KITTI flow PNGs carry a validity mask";
    const cv::Mat viz = cv::imread((dir / "out" / "seq" / "viz" / (std::string(stem) + ".png")).string());
    EXPECT_EQ(viz.cols, kWidth);
    EXPECT_EQ(viz.rows, kHeight);
  }
}

// --viz-mode overlay: each rendering blended over its pair's first frame at the element's 60 %
// (weight 154 of 256), the same colours --viz-mode flow draws alone.
TEST_F(ConvertCli, VizModeOverlayBlendsTheRenderingOverTheFirstFrame) {
  TempDir dir;
  const auto frames = make_frames(dir / "seq", {"a.png", "b.png"});
  ASSERT_EQ(convert(dir / "flow", {(dir / "seq").string(), "--viz", "png"}).exit_code, 0);
  const auto result = convert(dir / "over", {(dir / "seq").string(), "--viz", "png", "--viz-mode", "overlay"});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const cv::Mat alone = cv::imread((dir / "flow" / "seq" / "viz" / "a.png").string(), cv::IMREAD_COLOR);
  const cv::Mat over = cv::imread((dir / "over" / "seq" / "viz" / "a.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(alone.empty());
  ASSERT_EQ(over.size(), frames[0].size());
  int wrong = 0;
  for (int y = 0; y < over.rows; ++y) {
    for (int x = 0; x < over.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int expected =
            (frames[0].at<cv::Vec3b>(y, x)[c] * (256 - 154) + alone.at<cv::Vec3b>(y, x)[c] * 154 + 128) >> 8;
        wrong += over.at<cv::Vec3b>(y, x)[c] != expected ? 1 : 0;
      }
    }
  }
  EXPECT_EQ(wrong, 0) << "channels that are not the 60 % blend of the frame and the flow's colours";
  EXPECT_EQ(convert(dir / "bad", {(dir / "seq").string(), "--viz", "png", "--viz-mode", "arrows"}).exit_code, 64);
  EXPECT_EQ(convert(dir / "bad", {(dir / "seq").string(), "--viz-mode", "overlay"}).exit_code, 64)
      << "--viz-mode without --viz draws nothing";
}

TEST_F(ConvertCli, BgrChannelOrderFeedsTheNetworkSwappedChannels) {
  TempDir dir;
  auto images = make_frames(dir.path(), {"a.png", "b.png"});
  const auto result =
      convert(dir / "out", {(dir / "a.png").string(), (dir / "b.png").string(), "--channel-order", "bgr"});
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (auto& image : images) cv::cvtColor(image, image, cv::COLOR_BGR2RGB);
  // The reference reads the swapped images as BGR, so the network sees the original BGR as RGB.
  EXPECT_LT(max_difference(flow::read_flow(dir / "out" / "a_b" / "flow.flo"), reference_flow(images[0], images[1])),
            1e-4);
}

TEST_F(ConvertCli, SingleFrameAndEmptyFolderFail) {
  TempDir dir;
  make_frames(dir / "one", {"only.png"});
  fs::create_directories(dir / "empty");
  const auto result = convert(dir / "out", {(dir / "one").string(), (dir / "empty").string()});
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("a flow needs at least two"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("no image files"), std::string::npos) << result.output;
}

TEST_F(ConvertCli, MissingCheckpointFailsBeforeAnyInput) {
  TempDir dir;
  make_frames(dir / "seq", {"a.png", "b.png"});
  const auto result =
      run_neuflow({"convert", "-m", (dir / "none.pth").string(), "-o", (dir / "out").string(), (dir / "seq").string()});
  EXPECT_EQ(result.exit_code, 66) << result.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace neuflow::cli

namespace neuflow::cli {
namespace {

// Every file under `root` (relative path → bytes).
std::map<std::string, std::string> tree(const fs::path& root) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    std::ifstream in(entry.path(), std::ios::binary);
    files[fs::relative(entry.path(), root).string()] =
        std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return files;
}

// A job array splits the inputs with --shard K/N; what all the shards write is what one run
// writes, file for file and byte for byte.
TEST_F(ConvertCli, ShardsTogetherWriteWhatOneRunWrites) {
  TempDir dir;
  std::vector<std::string> inputs;
  for (const char* name : {"a", "b", "c"}) {
    make_frames(dir / "in" / name, {"0.png", "1.png"});
    inputs.push_back((dir / "in" / name).string());
  }
  // Two inputs with the same name get the suffixes of the whole run in every shard.
  make_frames(dir / "in" / "again" / "a", {"0.png", "1.png"});
  inputs.push_back((dir / "in" / "again" / "a").string());

  ASSERT_EQ(convert(dir / "whole", inputs).exit_code, 0);
  for (const char* shard : {"0/3", "1/3", "2/3"}) {
    auto args = inputs;
    args.insert(args.end(), {"--shard", shard});
    const auto result = convert(dir / "sharded", args);
    ASSERT_EQ(result.exit_code, 0) << shard << ": " << result.output;
  }
  const auto whole = tree(dir / "whole"), sharded = tree(dir / "sharded");
  EXPECT_EQ(whole.size(), 12u);  // 4 inputs × (1 flow + index.csv + settings.toml)
  EXPECT_TRUE(whole.count("a_2/0.flo")) << "the second 'a' is a_2";
  EXPECT_TRUE(whole == sharded) << "the shards wrote other files than the whole run";

  for (const char* bad : {"3/3", "1/0", "-1/2", "1", "a/b"}) {
    auto args = inputs;
    args.insert(args.end(), {"--shard", bad});
    EXPECT_EQ(convert(dir / "bad", args).exit_code, kExitUsage) << bad;
  }
}

// A long video split by frame ranges that meet (--frames 0:2, 2:4, 4:): every flow file of
// the whole run, byte for byte, and the ranges' indexes hold the whole run's rows.
TEST_F(ConvertCli, FrameRangesTogetherWriteWhatOneRunWrites) {
  TempDir dir;
  const auto video = test::make_test_video(dir / "ball.mp4", 6, kWidth, kHeight);
  ASSERT_EQ(convert(dir / "whole", {video.string()}).exit_code, 0);
  for (const char* range : {"0:2", "2:4", "4:"}) {
    const auto result = convert(dir / "ranges", {video.string(), "--frames", range});
    ASSERT_EQ(result.exit_code, 0) << range << ": " << result.output;
  }
  auto whole = tree(dir / "whole"), ranges = tree(dir / "ranges");
  EXPECT_EQ(whole.size(), 7u);  // 5 flows + index.csv + settings.toml
  EXPECT_TRUE(ranges.count("ball/index.0-2.csv") && ranges.count("ball/index.2-4.csv") &&
              ranges.count("ball/index.4-end.csv"));
  const auto whole_index = read_csv(dir / "whole" / "ball" / "index.csv");
  std::vector<std::vector<std::string>> joined{whole_index.front()};
  for (const char* name : {"index.0-2.csv", "index.2-4.csv", "index.4-end.csv"}) {
    const auto part = read_csv(dir / "ranges" / "ball" / name);
    ASSERT_FALSE(part.empty());
    EXPECT_EQ(part.front(), whole_index.front()) << name;
    joined.insert(joined.end(), part.begin() + 1, part.end());
    ranges.erase(std::string("ball/") + name);
  }
  EXPECT_EQ(joined, whole_index);
  whole.erase("ball/index.csv");
  EXPECT_TRUE(whole == ranges) << "the ranges wrote other flow files than the whole run";

  // A range past the input's end fails that input; malformed ranges are usage errors.
  const auto past = convert(dir / "past", {video.string(), "--frames", "9:12"});
  EXPECT_EQ(past.exit_code, kExitDataError) << past.output;
  EXPECT_NE(past.output.find("starts after its last"), std::string::npos) << past.output;
  for (const char* bad : {"3:3", "4:2", "-1:2", "2", "a:b", ":5"}) {
    EXPECT_EQ(convert(dir / "bad", {video.string(), "--frames", bad}).exit_code, kExitUsage) << bad;
  }
  EXPECT_EQ(convert(dir / "bad", {video.string(), "--frames", "0:2", "--max-frames", "3"}).exit_code, kExitUsage);
}

TEST(ConvertFrameRate, ImagesNamedByTheirCaptureTimeGiveTheirRate) {
  // The fixture camera's names: nanoseconds since the epoch, about 66.7 ms apart.
  const auto rate = rate_from_timestamps(
      {"1684437740861809471", "1684437740927818192", "1684437740994402386", "1684437741060823325"});
  ASSERT_TRUE(rate.known());
  EXPECT_NEAR(rate.fps(), 15.1, 0.05);
  EXPECT_NEAR(rate_from_timestamps({"1700000000000", "1700000000040", "1700000000080"}).fps(), 25.0, 1e-9);  // ms
  EXPECT_NEAR(rate_from_timestamps({"1700000000", "1700000002"}).fps(), 0.5, 1e-9);                          // s
  for (const std::vector<std::string>& none : {std::vector<std::string>{"frame_001", "frame_002"},
                                               {"0001", "0002"},
                                               {"1684437740861809471"},
                                               {"1684437740927818192", "1684437740861809471"},
                                               {"1700000000000", "17000000000400"}}) {
    EXPECT_FALSE(rate_from_timestamps(none).known()) << none.front();
  }
}

TEST_F(ConvertCli, VideoOfImagesPlaysAtTheirTimestampRateOrAtFps) {
  TempDir dir;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < 3; ++i) names.push_back(camera_frames_[i].filename().string());
  make_frames(dir / "camera", names);
  ASSERT_EQ(convert(dir / "out", {(dir / "camera").string(), "--viz", "video"}).exit_code, 0);
  {
    pipeline::VideoDecoder decoder((dir / "out" / "camera" / "viz.mp4").string());
    while (decoder.next()) {
    }
    EXPECT_NEAR(decoder.frame_rate().fps(), 15.1, 0.1) << "the fixture camera runs at about 15 fps";
  }
  ASSERT_EQ(convert(dir / "fps", {(dir / "camera").string(), "--viz", "video", "--fps", "25"}).exit_code, 0);
  pipeline::VideoDecoder decoder((dir / "fps" / "camera" / "viz.mp4").string());
  while (decoder.next()) {
  }
  EXPECT_EQ(decoder.frame_rate().numerator, 25);
  EXPECT_EQ(convert(dir / "bad", {(dir / "camera").string(), "--fps", "0"}).exit_code, kExitUsage);

  // The index gives each frame the time its name holds.
  const auto index = read_csv(dir / "out" / "camera" / "index.csv");
  ASSERT_EQ(index.size(), 3u);
  for (std::size_t row = 1; row < index.size(); ++row) {
    EXPECT_EQ(index[row][3], camera_frames_[row - 1].stem().string()) << "from_pts_ns of row " << row;
    EXPECT_EQ(index[row][4], camera_frames_[row].stem().string()) << "to_pts_ns of row " << row;
  }
}

TEST(ConvertFrameRate, NamesInSecondsToNanosecondsGiveCaptureTimesInNanoseconds) {
  EXPECT_EQ(capture_times_ns({"1700000000", "1700000002"}),
            (std::vector<std::int64_t>{1'700'000'000'000'000'000, 1'700'000'002'000'000'000}));
  EXPECT_EQ(capture_times_ns({"1700000000040"}), (std::vector<std::int64_t>{1'700'000'000'040'000'000}));
  EXPECT_TRUE(capture_times_ns({"9999999999999999999"}).empty()) << "past what ns in an int64 hold";
  EXPECT_TRUE(capture_times_ns({"frame_1"}).empty());
  EXPECT_TRUE(capture_times_ns({"1700000002", "1700000000"}).empty()) << "not increasing";
}

}  // namespace
}  // namespace neuflow::cli
