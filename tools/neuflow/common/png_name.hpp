#pragma once
// A CLI11 check for options that name a picture the command writes: PNG only, said by its name.
#include <string>

namespace neuflow::cli {

// Empty when `name` ends in .png (any case), else what to do (CLI11's check convention).
std::string png_name(const std::string& name);

}  // namespace neuflow::cli
