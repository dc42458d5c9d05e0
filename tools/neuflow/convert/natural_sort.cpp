#include "convert/natural_sort.hpp"

#include <cstddef>

namespace neuflow::cli {

namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// The digit run starting at `begin`, without its leading zeros (at least one digit kept).
std::string_view digit_run(std::string_view s, std::size_t begin, std::size_t& end) {
  end = begin;
  while (end < s.size() && is_digit(s[end])) ++end;
  std::size_t first = begin;
  while (first + 1 < end && s[first] == '0') ++first;
  return s.substr(first, end - first);
}

}  // namespace

bool natural_less(std::string_view a, std::string_view b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (is_digit(a[i]) && is_digit(b[j])) {
      std::size_t i_end = 0, j_end = 0;
      const std::string_view x = digit_run(a, i, i_end), y = digit_run(b, j, j_end);
      // Without leading zeros, the shorter number is the smaller; same length compares
      // digit by digit. No conversion, so runs longer than any integer type still work.
      if (x.size() != y.size()) return x.size() < y.size();
      if (x != y) return x < y;
      i = i_end;
      j = j_end;
    } else {
      if (a[i] != b[j]) return static_cast<unsigned char>(a[i]) < static_cast<unsigned char>(b[j]);
      ++i;
      ++j;
    }
  }
  const std::size_t rest_a = a.size() - i, rest_b = b.size() - j;
  if (rest_a != rest_b) return rest_a < rest_b;
  return a < b;
}

}  // namespace neuflow::cli
