#pragma once
// Tests of the Vulkan backend skip with a message when this machine has no Vulkan device
// (CI sets NEUFLOW_REQUIRE_VULKAN=1, which makes that a failure: it installs lavapipe), and
// expect the Khronos validation layer (NEUFLOW_VULKAN_VALIDATION=1, set by ctest) to stay quiet.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::test {

inline bool vulkan_required() {
  const char* env = std::getenv("NEUFLOW_REQUIRE_VULKAN");
  return env != nullptr && *env != '\0' && std::string(env) != "0";
}

// Empty when a device is there, else why not.
inline std::string vulkan_missing() {
  try {
    if (model::list_gpu_devices().empty()) return "Vulkan has no device here";
    return {};
  } catch (const model::BackendError& e) {
    return e.what();
  }
}

// True when only software devices (lavapipe) are there: speed tests skip, never fail, then.
inline bool only_software_vulkan() {
  try {
    for (const auto& d : model::list_gpu_devices()) {
      if (d.is_gpu()) return false;
    }
  } catch (const model::BackendError&) {
  }
  return true;
}

}  // namespace neuflow::test

#define NEUFLOW_REQUIRE_VULKAN()                                                                   \
  do {                                                                                            \
    const std::string neuflow_missing_ = ::neuflow::test::vulkan_missing();                       \
    if (!neuflow_missing_.empty()) {                                                              \
      if (::neuflow::test::vulkan_required()) FAIL() << neuflow_missing_;                         \
      GTEST_SKIP() << neuflow_missing_ << " (NEUFLOW_REQUIRE_VULKAN=1 makes this a failure)";     \
    }                                                                                             \
  } while (0)

#define NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES()                                                    \
  EXPECT_EQ(::neuflow::model::vulkan_validation_message_count(), 0u)                               \
      << "the Vulkan validation layer reported problems (printed above)"
