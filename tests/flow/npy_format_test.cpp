#include "neuflow/flow/npy_format.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

#include "test_util.hpp"

namespace neuflow::flow {
namespace {

using test::expect_flow_error;
using Kind = FlowFileError::Kind;

// An .npy file with the given header dict, version and raw data, padded as numpy pads.
std::vector<std::uint8_t> npy_bytes(const std::string& dict, std::size_t data_bytes, int major = 1) {
  const std::size_t prefix = major == 1 ? 10 : 12;
  std::string header = dict;
  header.append(64 - (prefix + header.size() + 1) % 64, ' ');
  header.push_back('\n');
  std::vector<std::uint8_t> b(prefix + header.size() + data_bytes, 0);
  std::memcpy(b.data(), "\x93NUMPY", 6);
  b[6] = static_cast<std::uint8_t>(major);
  b[8] = static_cast<std::uint8_t>(header.size() & 0xff);
  b[9] = static_cast<std::uint8_t>(header.size() >> 8);
  // Assembled with memcpy: GCC 12 at -O3 misreports vector::insert from a string
  // (-Wstringop-overflow false positive).
  std::memcpy(b.data() + prefix, header.data(), header.size());
  return b;
}

std::string f4_dict(const std::string& shape) {
  return "{'descr': '<f4', 'fortran_order': False, 'shape': " + shape + ", }";
}

TEST(NpyFormat, HeaderIsWhatNumpyWrites) {
  test::TempDir dir;
  write_npy(test::make_field(1024, 436), dir / "a.npy");
  const auto b = test::read_bytes(dir / "a.npy");
  ASSERT_GE(b.size(), 10u);
  EXPECT_EQ(std::string(b.begin(), b.begin() + 6), "\x93NUMPY");
  EXPECT_EQ(b[6], 1);
  EXPECT_EQ(b[7], 0);
  const std::size_t header_len = b[8] | (b[9] << 8);
  EXPECT_EQ((10 + header_len) % 64, 0u) << "data must start 64-byte aligned";
  const std::string header(b.begin() + 10, b.begin() + 10 + static_cast<std::ptrdiff_t>(header_len));
  EXPECT_EQ(header.rfind("{'descr': '<f4', 'fortran_order': False, 'shape': (436, 1024, 2), }", 0), 0u) << header;
  EXPECT_EQ(header.back(), '\n');
  EXPECT_EQ(b.size(), 10 + header_len + 8u * 1024 * 436);
}

TEST(NpyFormat, RoundTripIsBitExact) {
  test::TempDir dir;
  const FlowField f = test::make_field(31, 17);
  write_npy(f, dir / "a.npy");
  const FlowField g = read_npy(dir / "a.npy");
  EXPECT_EQ(g.width, 31);
  EXPECT_EQ(g.height, 17);
  EXPECT_EQ(g.uv, f.uv);
  EXPECT_FALSE(g.has_mask());
}

TEST(NpyFormat, MaskRoundTripsThroughNaN) {
  test::TempDir dir;
  const FlowField f = test::make_field(10, 6, /*with_mask=*/true);
  write_npy(f, dir / "m.npy");
  const FlowField g = read_npy(dir / "m.npy");
  ASSERT_TRUE(g.has_mask());
  EXPECT_EQ(g.valid, f.valid);
  for (std::size_t i = 0; i < f.pixel_count(); ++i) {
    EXPECT_EQ(g.uv[2 * i], f.valid[i] ? f.uv[2 * i] : 0.f);
    EXPECT_EQ(g.uv[2 * i + 1], f.valid[i] ? f.uv[2 * i + 1] : 0.f);
  }
}

TEST(NpyFormat, ReadsVersion2AndOddButValidHeaders) {
  test::TempDir dir;
  // Version 2.0 (4-byte header length), double quotes, no trailing comma, Python 2 longs.
  auto b = npy_bytes("{\"descr\": \"<f4\", \"shape\": (2L, 3L, 2L), \"fortran_order\": False}", 2 * 3 * 8, /*major=*/2);
  const std::size_t data = b.size() - 2 * 3 * 8;
  for (int i = 0; i < 12; ++i) {
    const float x = static_cast<float>(i) * 0.5f;
    std::memcpy(b.data() + data + 4 * static_cast<std::size_t>(i), &x, 4);
  }
  test::write_bytes(dir / "v2.npy", b);
  const FlowField g = read_npy(dir / "v2.npy");
  EXPECT_EQ(g.width, 3);
  EXPECT_EQ(g.height, 2);
  EXPECT_EQ(g.u(1, 0), 1.f);
  EXPECT_EQ(g.v(2, 1), 5.5f);
}

TEST(NpyFormatErrors, WrongMagic) {
  test::TempDir dir;
  auto b = npy_bytes(f4_dict("(1, 1, 2)"), 8);
  b[1] = 'X';
  test::write_bytes(dir / "a.npy", b);
  expect_flow_error([&] { read_npy(dir / "a.npy"); }, Kind::malformed, dir / "a.npy", "wrong magic");
}

TEST(NpyFormatErrors, WrongDtype) {
  test::TempDir dir;
  test::write_bytes(dir / "d.npy", npy_bytes("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2, 2), }", 64));
  expect_flow_error([&] { read_npy(dir / "d.npy"); }, Kind::malformed, dir / "d.npy",
                    "dtype '<f8' (float64) is not supported");
  test::write_bytes(dir / "b.npy", npy_bytes("{'descr': '>f4', 'fortran_order': False, 'shape': (2, 2, 2), }", 32));
  expect_flow_error([&] { read_npy(dir / "b.npy"); }, Kind::malformed, dir / "b.npy", "big-endian float32");
}

TEST(NpyFormatErrors, WrongShape) {
  test::TempDir dir;
  const char* shapes[] = {"(2, 4, 4)", "(4, 4)", "(4, 4, 3)", "(1, 4, 4, 2)", "()", "(32,)"};
  for (const char* shape : shapes) {
    test::write_bytes(dir / "s.npy", npy_bytes(f4_dict(shape), 128));
    expect_flow_error([&] { read_npy(dir / "s.npy"); }, Kind::malformed, dir / "s.npy",
                      std::string("array shape ") + shape + " is not a flow field");
  }
}

TEST(NpyFormatErrors, FortranOrder) {
  test::TempDir dir;
  test::write_bytes(dir / "f.npy", npy_bytes("{'descr': '<f4', 'fortran_order': True, 'shape': (2, 2, 2), }", 32));
  expect_flow_error([&] { read_npy(dir / "f.npy"); }, Kind::malformed, dir / "f.npy", "Fortran-order");
}

TEST(NpyFormatErrors, TruncatedAndTrailingData) {
  test::TempDir dir;
  test::write_bytes(dir / "t.npy", npy_bytes(f4_dict("(3, 3, 2)"), 71));
  expect_flow_error([&] { read_npy(dir / "t.npy"); }, Kind::malformed, dir / "t.npy",
                    "truncated: shape (3, 3, 2) needs");
  test::write_bytes(dir / "l.npy", npy_bytes(f4_dict("(3, 3, 2)"), 73));
  expect_flow_error([&] { read_npy(dir / "l.npy"); }, Kind::malformed, dir / "l.npy", "trailing data");
  test::write_bytes(dir / "h.npy", {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0, 0x80, 0});
  expect_flow_error([&] { read_npy(dir / "h.npy"); }, Kind::malformed, dir / "h.npy", "header length");
  test::write_bytes(dir / "s.npy", {0x93, 'N', 'U'});
  expect_flow_error([&] { read_npy(dir / "s.npy"); }, Kind::malformed, dir / "s.npy", "truncated");
}

TEST(NpyFormatErrors, AbsurdShapeIsRefusedBeforeAllocating) {
  test::TempDir dir;
  test::write_bytes(dir / "a.npy", npy_bytes(f4_dict("(100000, 100000, 2)"), 0));
  expect_flow_error([&] { read_npy(dir / "a.npy"); }, Kind::malformed, dir / "a.npy", "implausible flow size");
  test::write_bytes(dir / "b.npy", npy_bytes(f4_dict("(99999999999999999999, 1, 2)"), 0));
  expect_flow_error([&] { read_npy(dir / "b.npy"); }, Kind::malformed, dir / "b.npy", "too large");
  test::write_bytes(dir / "c.npy", npy_bytes(f4_dict("(16384, 16384, 2)"), 8));
  expect_flow_error([&] { read_npy(dir / "c.npy"); }, Kind::malformed, dir / "c.npy", "truncated");
}

TEST(NpyFormatErrors, UnsupportedVersionAndBrokenHeader) {
  test::TempDir dir;
  auto b = npy_bytes(f4_dict("(1, 1, 2)"), 8);
  b[6] = 9;
  test::write_bytes(dir / "v.npy", b);
  expect_flow_error([&] { read_npy(dir / "v.npy"); }, Kind::malformed, dir / "v.npy", "version 9.0");
  test::write_bytes(dir / "p.npy", npy_bytes("{'descr': '<f4', 'shape': [1, 1, 2]", 8));
  expect_flow_error([&] { read_npy(dir / "p.npy"); }, Kind::malformed, dir / "p.npy", "cannot parse the .npy header");
  test::write_bytes(dir / "k.npy", npy_bytes("{'descr': '<f4', 'shape': (1, 1, 2)}", 8));
  expect_flow_error([&] { read_npy(dir / "k.npy"); }, Kind::malformed, dir / "k.npy", "exactly the keys");
}

// --- Interoperability with numpy itself -------------------------------------------------

class NumpyInterop : public ::testing::Test {
 protected:
  void SetUp() override {
    python_ = NEUFLOW_PYTHON3;
    if (python_.empty() || !std::filesystem::exists(python_)) {
      GTEST_SKIP() << "no python3 interpreter was found at configure time (looked in /usr/bin "
                      "first); install python3 and python3-numpy to run this test";
    }
    if (run("-c 'import numpy'") != 0) {
      GTEST_SKIP() << python_ << " cannot import numpy; install python3-numpy to run this test";
    }
  }

  // Runs the interpreter with the given (shell-quoted) arguments; returns its exit status.
  int run(const std::string& args) const {
    const std::string cmd = "'" + python_ + "' " + args;
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  int run_script(const std::string& script, const std::filesystem::path& arg) const {
    const auto path = dir_ / "script.py";
    std::ofstream(path) << script;
    return run("'" + path.string() + "' '" + arg.string() + "'");
  }

  std::string python_;
  test::TempDir dir_;
};

TEST_F(NumpyInterop, NumpyLoadsWhatWeWrite) {
  const FlowField f = test::make_field(37, 23, /*with_mask=*/true);
  write_npy(f, dir_ / "ours.npy");
  // The script recomputes test::make_field's values in float32 and compares exactly.
  const std::string script = R"(
import sys
import numpy as np
a = np.load(sys.argv[1])
assert a.dtype == np.float32, a.dtype
assert a.shape == (23, 37, 2), a.shape
assert a.flags['C_CONTIGUOUS']
y, x = np.mgrid[0:23, 0:37].astype(np.float32)
u = np.float32(0.25) * x - np.float32(3.5) + np.float32(0.001) * y
v = np.float32(-0.5) * y + np.float32(1.75) - np.float32(0.002) * x
invalid = (np.arange(23 * 37) % 7 == 0).reshape(23, 37)
assert np.array_equal(np.isnan(a[..., 0]), invalid)
assert np.array_equal(np.isnan(a[..., 1]), invalid)
assert np.allclose(a[..., 0][~invalid], u[~invalid], rtol=0, atol=1e-6)
assert np.allclose(a[..., 1][~invalid], v[~invalid], rtol=0, atol=1e-6)
assert a[0, 1, 0] == np.float32(-3.25) and a[1, 0, 1] == np.float32(1.25)
)";
  EXPECT_EQ(run_script(script, dir_ / "ours.npy"), 0) << "numpy rejected or misread our .npy";
}

TEST_F(NumpyInterop, WeReadWhatNumpyWrites) {
  const std::string script = R"(
import sys, os
import numpy as np
d = sys.argv[1]
a = np.zeros((5, 7, 2), np.float32)
a[..., 0] = np.arange(35, dtype=np.float32).reshape(5, 7) * 0.5
a[..., 1] = -np.arange(35, dtype=np.float32).reshape(5, 7)
a[2, 3, :] = np.nan
np.save(os.path.join(d, 'v1.npy'), a)
with open(os.path.join(d, 'v2.npy'), 'wb') as f:
    np.lib.format.write_array(f, a, version=(2, 0))
np.save(os.path.join(d, 'f8.npy'), a.astype(np.float64))
np.save(os.path.join(d, 'chw.npy'), np.ascontiguousarray(a.transpose(2, 0, 1)))
np.save(os.path.join(d, 'fortran.npy'), np.asfortranarray(a))
)";
  ASSERT_EQ(run_script(script, dir_.path()), 0);
  for (const char* name : {"v1.npy", "v2.npy"}) {
    SCOPED_TRACE(name);
    const FlowField g = read_npy(dir_ / name);
    ASSERT_EQ(g.width, 7);
    ASSERT_EQ(g.height, 5);
    EXPECT_EQ(g.u(6, 4), 17.f);
    EXPECT_EQ(g.v(6, 4), -34.f);
    ASSERT_TRUE(g.has_mask());
    EXPECT_FALSE(g.is_valid(3, 2));
    EXPECT_EQ(std::count(g.valid.begin(), g.valid.end(), 0), 1);
  }
  expect_flow_error([&] { read_npy(dir_ / "f8.npy"); }, Kind::malformed, dir_ / "f8.npy", "float64");
  expect_flow_error([&] { read_npy(dir_ / "chw.npy"); }, Kind::malformed, dir_ / "chw.npy", "array shape (2, 5, 7)");
  expect_flow_error([&] { read_npy(dir_ / "fortran.npy"); }, Kind::malformed, dir_ / "fortran.npy", "Fortran-order");
}

TEST(NpyArray, ReadsAnyRankAndChecksTheShapeBeforeTheData) {
  test::TempDir dir;
  std::vector<std::uint8_t> data(24);
  for (int i = 0; i < 6; ++i) {
    const float v = 0.5f * static_cast<float>(i);
    std::memcpy(data.data() + 4 * i, &v, 4);
  }
  auto bytes = npy_bytes(f4_dict("(2, 3)"), 0);
  bytes.insert(bytes.end(), data.begin(), data.end());
  test::write_bytes(dir / "a.npy", bytes);
  const NpyArray a = read_npy_array(dir / "a.npy");
  EXPECT_EQ(a.shape, (std::vector<std::int64_t>{2, 3}));
  ASSERT_EQ(a.data.size(), 6u);
  EXPECT_EQ(a.data[5], 2.5f);

  // A truncated file is refused by the check first, with the check's own error.
  test::write_bytes(dir / "t.npy", npy_bytes(f4_dict("(1, 2, 3, 4)"), 8));
  bool checked = false;
  EXPECT_THROW(read_npy_array(dir / "t.npy",
                              [&](const std::vector<std::int64_t>& shape) {
                                checked = true;
                                EXPECT_EQ(shape.size(), 4u);
                                throw std::invalid_argument("refused");
                              }),
               std::invalid_argument);
  EXPECT_TRUE(checked);
  expect_flow_error([&] { read_npy_array(dir / "t.npy"); }, Kind::malformed, dir / "t.npy", "truncated");
}

}  // namespace
}  // namespace neuflow::flow
