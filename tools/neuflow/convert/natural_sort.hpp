#pragma once
// Natural order for frame file names: runs of digits compare by their value, so frame2
// comes before frame10 (plain string order puts frame10 first and scrambles the sequence).
#include <string_view>

namespace neuflow::cli {

// A strict weak ordering. Names that differ only in leading zeros ("frame01", "frame1")
// are ordered by their plain string order, so no two distinct names compare equal.
bool natural_less(std::string_view a, std::string_view b);

}  // namespace neuflow::cli
