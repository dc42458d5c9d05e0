#pragma once
// Tests of the Vulkan backend skip with a message when this machine has no Vulkan device
// (CI sets NEUFLOW_REQUIRE_VULKAN=1, which makes that a failure: it installs lavapipe), and
// expect the Khronos validation layer (NEUFLOW_VULKAN_VALIDATION=1, set by ctest) to stay quiet.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <string_view>

#include "neuflow/model/device_work.hpp"
#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::test {

inline bool vulkan_required() {
  const char* env = std::getenv("NEUFLOW_REQUIRE_VULKAN");
  return env != nullptr && *env != '\0' && std::string(env) != "0";
}

// Non-empty when this process runs LeakSanitizer with its slow unwinder (what the GStreamer
// tests' suppressions need): lavapipe's LLVM JIT registers its code's unwind tables under
// libgcc's lock and allocates while holding it, and LSan's unwind of that allocation waits for
// the same lock, so a Vulkan test there hangs until ctest's timeout. Failing at once says which
// list the test belongs in instead.
inline std::string vulkan_deadlocks_under_lsan() {
  const char* lsan = std::getenv("LSAN_OPTIONS");
  const char* asan = std::getenv("ASAN_OPTIONS");
  const bool slow_unwinder = lsan != nullptr && std::string(lsan).find("fast_unwind_on_malloc=0") != std::string::npos;
  const bool leaks_checked = asan == nullptr || std::string(asan).find("detect_leaks=0") == std::string::npos;
  if (!slow_unwinder || !leaks_checked) return {};
  return "this Vulkan test runs under LeakSanitizer's slow unwinder (LSAN_OPTIONS=...fast_unwind_on_malloc=0), "
         "which deadlocks against lavapipe's JIT: run it with ASAN_OPTIONS=detect_leaks=0, as "
         "tests/plugins/CMakeLists.txt does for the tests that element_vulkan_tests selects";
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

// How many of a pass's commands ran `kernel` (DeviceWork's command names).
inline long dispatches_of(const model::DeviceWork& work, std::string_view kernel) {
  return static_cast<long>(std::count_if(work.commands.begin(), work.commands.end(),
                                         [&](const model::DeviceCommand& c) { return c.kernel == kernel; }));
}

}  // namespace neuflow::test

#define NEUFLOW_REQUIRE_VULKAN()                                                              \
  do {                                                                                        \
    const std::string neuflow_deadlock_ = ::neuflow::test::vulkan_deadlocks_under_lsan();     \
    if (!neuflow_deadlock_.empty()) FAIL() << neuflow_deadlock_;                              \
    const std::string neuflow_missing_ = ::neuflow::test::vulkan_missing();                   \
    if (!neuflow_missing_.empty()) {                                                          \
      if (::neuflow::test::vulkan_required()) FAIL() << neuflow_missing_;                     \
      GTEST_SKIP() << neuflow_missing_ << " (NEUFLOW_REQUIRE_VULKAN=1 makes this a failure)"; \
    }                                                                                         \
  } while (0)

#define NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES()                      \
  EXPECT_EQ(::neuflow::model::vulkan_validation_message_count(), 0u) \
      << "the Vulkan validation layer reported problems (printed above)"
