#include "neuflow/flow/flow_io.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include "test_util.hpp"

namespace neuflow::flow {
namespace {

using test::expect_flow_error;
using Kind = FlowFileError::Kind;

std::string file_start(const std::filesystem::path& path, std::size_t n) {
  const auto b = test::read_bytes(path);
  return std::string(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(std::min(n, b.size())));
}

TEST(FlowIo, FormatFromExtension) {
  EXPECT_EQ(flow_format_from_path("a/b.flo"), FlowFormat::flo);
  EXPECT_EQ(flow_format_from_path("B.FLO"), FlowFormat::flo);
  EXPECT_EQ(flow_format_from_path("x.png"), FlowFormat::kitti_png);
  EXPECT_EQ(flow_format_from_path("x.Npy"), FlowFormat::npy);
  EXPECT_EQ(flow_format_from_path("x.jpg"), std::nullopt);
  EXPECT_EQ(flow_format_from_path("flo"), std::nullopt);
  EXPECT_EQ(flow_format_from_path("x.flo.gz"), std::nullopt);
}

TEST(FlowIo, DispatchesByExtension) {
  test::TempDir dir;
  FlowField f(6, 4);
  for (std::size_t i = 0; i < f.uv.size(); ++i) f.uv[i] = static_cast<float>(i) / 64.f - 0.5f;
  write_flow(f, dir / "a.flo");
  write_flow(f, dir / "a.PNG");
  write_flow(f, dir / "a.npy");
  EXPECT_EQ(file_start(dir / "a.flo", 4), "PIEH");
  EXPECT_EQ(file_start(dir / "a.PNG", 4), "\x89PNG");
  EXPECT_EQ(file_start(dir / "a.npy", 6), "\x93NUMPY");
  for (const char* name : {"a.flo", "a.PNG", "a.npy"}) {
    SCOPED_TRACE(name);
    const FlowField g = read_flow(dir / name);
    EXPECT_EQ(g.uv, f.uv);  // the values are on KITTI's 1/64 grid, so even PNG is exact
    EXPECT_EQ(g.width, 6);
    EXPECT_EQ(g.height, 4);
  }
}

TEST(FlowIo, MasksRoundTripInEveryFormat) {
  test::TempDir dir;
  FlowField f(9, 9);
  f.valid.assign(f.pixel_count(), 1);
  for (std::size_t i = 0; i < f.pixel_count(); ++i) {
    f.uv[2 * i] = static_cast<float>(i % 9) * 0.5f;
    f.uv[2 * i + 1] = -static_cast<float>(i / 9) * 0.25f;
    if (i % 5 == 2) f.valid[i] = 0;
  }
  for (const char* name : {"m.flo", "m.png", "m.npy"}) {
    SCOPED_TRACE(name);
    write_flow(f, dir / name);
    const FlowField g = read_flow(dir / name);
    EXPECT_EQ(g.valid, f.valid);
    for (std::size_t i = 0; i < f.pixel_count(); ++i) {
      if (f.valid[i]) {
        EXPECT_EQ(g.uv[2 * i], f.uv[2 * i]);
      }
    }
  }
}

TEST(FlowIo, UnknownExtension) {
  test::TempDir dir;
  test::write_bytes(dir / "a.jpg", {1, 2, 3});
  expect_flow_error([&] { read_flow(dir / "a.jpg"); }, Kind::unsupported_format, dir / "a.jpg",
                    "unknown flow file extension '.jpg' (expected .flo, .png or .npy)");
  expect_flow_error([&] { write_flow(FlowField(2, 2), dir / "b.txt"); }, Kind::unsupported_format, dir / "b.txt",
                    "unknown flow file extension");
  test::write_bytes(dir / "noext", {1});
  expect_flow_error([&] { read_flow(dir / "noext"); }, Kind::unsupported_format, dir / "noext", "no file extension");
  EXPECT_FALSE(std::filesystem::exists(dir / "b.txt"));
}

TEST(FlowIo, MissingFileWinsOverUnknownExtension) {
  test::TempDir dir;
  expect_flow_error([&] { read_flow(dir / "typo.fl"); }, Kind::not_found, dir / "typo.fl", "no such file");
  expect_flow_error([&] { read_flow(dir / "none.flo"); }, Kind::not_found, dir / "none.flo", "no such file");
}

TEST(FlowIo, WriteReplacesAnExistingFileAndLeavesNoTemporary) {
  test::TempDir dir;
  for (const char* name : {"r.flo", "r.png", "r.npy"}) {
    test::write_bytes(dir / name, {'o', 'l', 'd'});
    write_flow(test::make_field(5, 3), dir / name);
    EXPECT_EQ(read_flow(dir / name).width, 5);
  }
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"r.flo", "r.npy", "r.png"}));
}

TEST(FlowIo, FailedWriteThrowsAndLeavesNoTemporary) {
  test::TempDir dir;
  // rename() cannot replace a directory: the data is written, the final step fails.
  std::filesystem::create_directory(dir / "taken.flo");
  expect_flow_error([&] { write_flow(test::make_field(4, 4), dir / "taken.flo"); }, Kind::write_failed,
                    dir / "taken.flo", "cannot replace");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"taken.flo"}));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "taken.flo"));

  expect_flow_error([&] { write_flow(test::make_field(4, 4), dir / "no" / "such" / "dir.npy"); }, Kind::write_failed,
                    dir / "no" / "such" / "dir.npy", "cannot create");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"taken.flo"}));
}

TEST(FlowIo, ReadOnlyDirectory) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions do not stop writes";
  test::TempDir dir;
  std::filesystem::create_directory(dir / "ro");
  std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  expect_flow_error([&] { write_flow(test::make_field(4, 4), dir / "ro" / "x.png"); }, Kind::write_failed,
                    dir / "ro" / "x.png", "Permission denied");
  std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_all);
  EXPECT_TRUE(std::filesystem::is_empty(dir / "ro"));
}

TEST(FlowIo, FileErrorCarriesPathAndProblem) {
  const FlowFileError e(FlowFileError::Kind::malformed, "/x/y.flo", "wrong magic");
  EXPECT_STREQ(e.what(), "/x/y.flo: wrong magic");
  EXPECT_EQ(e.problem(), "wrong magic");
  EXPECT_EQ(e.path(), std::filesystem::path("/x/y.flo"));
  const std::runtime_error& base = e;  // catchable as a runtime_error
  EXPECT_STREQ(base.what(), "/x/y.flo: wrong magic");
}

}  // namespace
}  // namespace neuflow::flow
