#pragma once
// Force-included (-include) into every fuzz-build source that can see toml++: its assertions
// (TOML_ASSERT, and TOML_ASSERT_ASSUME, which is TOML_ASSERT without NDEBUG) report through
// neuflow_fuzz_toml_assert (toml_impl.cpp) instead of assert(). An assertion not listed there
// as known is a finding (abort); a known one is reported once and let through.
void neuflow_fuzz_toml_assert(const char* expression, const char* file, int line, const char* function);

#define TOML_ASSERT(expr) \
  (static_cast<bool>(expr) ? static_cast<void>(0) : neuflow_fuzz_toml_assert(#expr, __FILE__, __LINE__, __func__))
