#include <gtest/gtest.h>

#include <fstream>

#include "common/exit_codes.hpp"
#include "convert/inputs.hpp"
#include "support/temp_dir.hpp"
#include "test_media.hpp"

namespace neuflow::cli {
namespace {

using test::TempDir;

void touch(const std::filesystem::path& p) { std::ofstream(p) << "x"; }

TEST(PlanInputs, TwoImagesFormAPair) {
  TempDir dir;
  touch(dir / "a.png");
  touch(dir / "b.JPG");
  const auto specs = plan_inputs({(dir / "a.png").string(), (dir / "b.JPG").string()}, {});
  ASSERT_EQ(specs.size(), 1u);
  EXPECT_EQ(specs[0].kind, InputKind::image_pair);
  EXPECT_EQ(specs[0].output_name, "a_b");
  EXPECT_FALSE(specs[0].rejected);
}

TEST(PlanInputs, FoldersVideosAndPairsTogether) {
  TempDir dir;
  std::filesystem::create_directories(dir / "frames");
  touch(dir / "clip.avi");
  const auto specs = plan_inputs({(dir / "frames").string() + "/", (dir / "clip.avi").string()},
                                 {{(dir / "x.png").string(), (dir / "y.png").string()}});
  ASSERT_EQ(specs.size(), 3u);
  EXPECT_EQ(specs[0].kind, InputKind::image_pair);
  EXPECT_EQ(specs[0].output_name, "x_y");
  EXPECT_EQ(specs[1].kind, InputKind::image_folder);
  EXPECT_EQ(specs[1].output_name, "frames");  // the trailing slash does not matter
  EXPECT_EQ(specs[2].kind, InputKind::video);
  EXPECT_EQ(specs[2].output_name, "clip");
}

TEST(PlanInputs, SameNamesGetStableSuffixes) {
  TempDir dir;
  std::filesystem::create_directories(dir / "one");
  std::filesystem::create_directories(dir / "two");
  touch(dir / "one" / "clip.mp4");
  touch(dir / "two" / "clip.mp4");
  touch(dir / "clip.mkv");
  const auto specs = plan_inputs(
      {(dir / "one" / "clip.mp4").string(), (dir / "two" / "clip.mp4").string(), (dir / "clip.mkv").string()}, {});
  ASSERT_EQ(specs.size(), 3u);
  EXPECT_EQ(specs[0].output_name, "clip");
  EXPECT_EQ(specs[1].output_name, "clip_2");
  EXPECT_EQ(specs[2].output_name, "clip_3");
}

TEST(PlanInputs, UrisAreVideosNamedAfterTheirLastSegment) {
  const auto specs =
      plan_inputs({"https://example.com/media/street.mp4?token=1", "rtsp://camera.local/", "file:///"}, {});
  ASSERT_EQ(specs.size(), 3u);
  EXPECT_EQ(specs[0].kind, InputKind::video);
  EXPECT_EQ(specs[0].output_name, "street");
  EXPECT_FALSE(specs[0].rejected);
  EXPECT_EQ(specs[1].output_name, "camera");  // no path: the host, without its domain
  EXPECT_EQ(specs[2].output_name, "input");   // nothing to name it after
}

TEST(PlanInputs, MissingPathIsRejectedAsNoInput) {
  TempDir dir;
  const auto specs = plan_inputs({(dir / "missing.mp4").string()}, {});
  ASSERT_EQ(specs.size(), 1u);
  ASSERT_TRUE(specs[0].rejected);
  EXPECT_EQ(specs[0].rejected->exit_code, kExitNoInput);
  EXPECT_NE(std::string(specs[0].rejected->what()).find("no such file"), std::string::npos);
}

TEST(PlanInputs, LoneImagesAreRejectedWithAHint) {
  TempDir dir;
  for (const char* name : {"a.png", "b.png", "c.png"}) touch(dir / name);
  const auto specs = plan_inputs({(dir / "a.png").string(), (dir / "b.png").string(), (dir / "c.png").string()}, {});
  ASSERT_EQ(specs.size(), 3u);
  for (const auto& spec : specs) {
    ASSERT_TRUE(spec.rejected) << spec.label;
    EXPECT_NE(std::string(spec.rejected->what()).find("--pair"), std::string::npos);
  }
}

TEST(PlanInputs, ImageExtensions) {
  EXPECT_TRUE(has_image_extension("x/frame.PNG"));
  EXPECT_TRUE(has_image_extension("frame.jpeg"));
  EXPECT_FALSE(has_image_extension("clip.mp4"));
  EXPECT_FALSE(has_image_extension("png"));
}

}  // namespace
}  // namespace neuflow::cli
