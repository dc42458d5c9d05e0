// VideoEncoder: what it writes decodes back to the same number of frames, size and colours;
// the target path only ever holds a finished file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "neuflow/pipeline/pipeline_error.hpp"
#include "neuflow/pipeline/video_decoder.hpp"
#include "neuflow/pipeline/video_encoder.hpp"
#include "support/temp_dir.hpp"
#include "test_media.hpp"

namespace neuflow::pipeline {
namespace {

using test::TempDir;

flow::RgbImage solid(int width, int height, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  flow::RgbImage image{width, height, {}};
  for (int i = 0; i < width * height; ++i) image.rgb.insert(image.rgb.end(), {r, g, b});
  return image;
}

std::vector<RgbFrame> decode_all(const std::filesystem::path& path) {
  VideoDecoder decoder(path.string());
  std::vector<RgbFrame> frames;
  while (auto frame = decoder.next()) frames.push_back(std::move(*frame));
  return frames;
}

double mean_channel(const RgbFrame& frame, int channel) {
  double sum = 0;
  for (std::size_t i = static_cast<std::size_t>(channel); i < frame.rgb.size(); i += 3) sum += frame.rgb[i];
  return sum / (frame.rgb.size() / 3);
}

void encode_colours(const std::filesystem::path& path, int width, int height, int frames) {
  VideoEncoder encoder(path, width, height, FrameRate{10, 1});
  for (int i = 0; i < frames; ++i) {
    encoder.write(
        solid(width, height, static_cast<std::uint8_t>(40 * i), 128, static_cast<std::uint8_t>(200 - 30 * i)));
  }
  EXPECT_FALSE(std::filesystem::exists(path)) << "visible before finish()";
  encoder.finish();
  EXPECT_EQ(encoder.frames_written(), frames);
}

TEST(VideoEncoder, Mp4DecodesBackToTheSameFramesAndColours) {
  TempDir dir;
  const auto path = dir / "viz.mp4";
  encode_colours(path, 64, 48, 5);
  const auto frames = decode_all(path);
  ASSERT_EQ(frames.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(frames[i].width, 64);
    EXPECT_EQ(frames[i].height, 48);
    // 4:2:0 and H.264 quantization move solid colours by a few levels at most.
    EXPECT_NEAR(mean_channel(frames[i], 0), 40 * i, 6) << "frame " << i;
    EXPECT_NEAR(mean_channel(frames[i], 1), 128, 6) << "frame " << i;
    EXPECT_NEAR(mean_channel(frames[i], 2), 200 - 30 * i, 6) << "frame " << i;
  }
  EXPECT_EQ(test::hidden_files(dir.path()), "");
}

TEST(VideoEncoder, MatroskaToo) {
  TempDir dir;
  const auto path = dir / "viz.mkv";
  encode_colours(path, 32, 32, 3);
  EXPECT_EQ(decode_all(path).size(), 3u);
}

TEST(VideoEncoder, OddSizesAreEncodedOnePixelLarger) {
  TempDir dir;
  const auto path = dir / "odd.mp4";
  encode_colours(path, 65, 49, 2);
  const auto frames = decode_all(path);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].width, 66);
  EXPECT_EQ(frames[0].height, 50);
  // The padding repeats the edge, so the colour is the same everywhere.
  EXPECT_NEAR(mean_channel(frames[0], 2), 200, 6);
}

TEST(VideoEncoder, AbandonedEncoderLeavesTheTargetUntouched) {
  TempDir dir;
  const auto path = dir / "viz.mp4";
  std::ofstream(path) << "previous file";
  {
    VideoEncoder encoder(path, 32, 32, FrameRate{});
    encoder.write(solid(32, 32, 1, 2, 3));
  }
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "previous file");
  EXPECT_EQ(test::hidden_files(dir.path()), "");
}

TEST(VideoEncoder, FinishWithoutFramesFails) {
  TempDir dir;
  const auto path = dir / "empty.mp4";
  VideoEncoder encoder(path, 32, 32, FrameRate{25, 1});
  EXPECT_THROW(encoder.finish(), PipelineError);
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_EQ(test::hidden_files(dir.path()), "");
}

TEST(VideoEncoder, RejectsUnknownExtension) {
  TempDir dir;
  try {
    VideoEncoder encoder(dir / "viz.avi", 32, 32, FrameRate{});
    FAIL() << "no exception";
  } catch (const PipelineError& e) {
    EXPECT_EQ(e.kind(), PipelineError::Kind::invalid_argument);
    EXPECT_NE(std::string(e.what()).find(".mp4 or .mkv"), std::string::npos) << e.what();
  }
}

TEST(VideoEncoder, MissingFolderIsAWriteFailureNamingTheFile) {
  TempDir dir;
  const auto path = dir / "no-such-folder" / "viz.mp4";
  try {
    VideoEncoder encoder(path, 32, 32, FrameRate{});
    FAIL() << "no exception";
  } catch (const PipelineError& e) {
    EXPECT_EQ(e.kind(), PipelineError::Kind::write_failed);
    EXPECT_EQ(e.subject(), path.string());
  }
}

TEST(VideoEncoder, RejectsFramesOfAnotherSize) {
  TempDir dir;
  VideoEncoder encoder(dir / "viz.mp4", 32, 32, FrameRate{});
  try {
    encoder.write(solid(16, 32, 0, 0, 0));
    FAIL() << "no exception";
  } catch (const PipelineError& e) {
    EXPECT_EQ(e.kind(), PipelineError::Kind::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("16x32"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace neuflow::pipeline
