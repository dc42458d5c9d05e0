#pragma once
// Helpers shared by the flow tests: scratch directories, raw file bytes, sample fields.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::flow::test {

// A fresh directory per test, removed afterwards.
using neuflow::test::TempDir;

inline void write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline std::vector<std::uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void append_i32(std::vector<std::uint8_t>& out, std::int32_t v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, 4);
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
}
inline void append_f32(std::vector<std::uint8_t>& out, float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, 4);
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
}

// A field with distinct, non-integer values everywhere (so any transposition or channel
// swap shows), optionally with a mask that marks every 7th pixel invalid.
inline FlowField make_field(int width, int height, bool with_mask = false) {
  FlowField f(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      f.u(x, y) = 0.25f * static_cast<float>(x) - 3.5f + 0.001f * static_cast<float>(y);
      f.v(x, y) = -0.5f * static_cast<float>(y) + 1.75f - 0.002f * static_cast<float>(x);
    }
  }
  if (with_mask) {
    f.valid.assign(f.pixel_count(), 1);
    for (std::size_t i = 0; i < f.valid.size(); i += 7) f.valid[i] = 0;
  }
  return f;
}

// A field of one vector (u, v) everywhere, without a mask.
inline FlowField constant_field(int width, int height, float u, float v) {
  FlowField f(width, height);
  for (std::size_t i = 0; i < f.pixel_count(); ++i) {
    f.uv[2 * i] = u;
    f.uv[2 * i + 1] = v;
  }
  return f;
}

// Runs fn, expecting a FlowFileError of the given kind whose message names path and
// contains `fragment`.
template <class Fn>
void expect_flow_error(Fn&& fn, FlowFileError::Kind kind, const std::filesystem::path& path,
                       const std::string& fragment) {
  try {
    fn();
    ADD_FAILURE() << "expected FlowFileError containing '" << fragment << "'";
  } catch (const FlowFileError& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
        << "message '" << e.what() << "' lacks '" << fragment << "'";
  }
}

}  // namespace neuflow::flow::test
