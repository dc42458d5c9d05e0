#include "neuflow/flow/npy_format.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "binary.hpp"
#include "field_check.hpp"
#include "file_io.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/limits.hpp"

namespace neuflow::flow {

namespace {

using Kind = FlowFileError::Kind;

constexpr char kMagic[6] = {'\x93', 'N', 'U', 'M', 'P', 'Y'};
constexpr std::size_t kAlign = 64;                  // numpy pads the header to this since 1.14
constexpr std::uint32_t kMaxHeaderBytes = 1 << 20;  // numpy itself refuses > 10000 by default

using Shape = std::vector<std::int64_t>;
using HeaderValue = std::variant<std::string, bool, Shape>;

// Parser for the Python dict literal of an .npy header, e.g.
//   {'descr': '<f4', 'fortran_order': False, 'shape': (436, 1024, 2), }
// It understands exactly the literals numpy writes there: quoted strings, True/False and
// tuples of integers (optionally with Python 2's L suffix).
class HeaderParser {
 public:
  HeaderParser(std::string_view text, const std::filesystem::path& path) : s_(text), path_(path) {}

  std::map<std::string, HeaderValue> parse() {
    std::map<std::string, HeaderValue> dict;
    skip_space();
    expect('{');
    while (true) {
      skip_space();
      if (peek() == '}') break;
      std::string key = parse_string();
      skip_space();
      expect(':');
      skip_space();
      dict[key] = parse_value();
      skip_space();
      if (peek() == ',') {
        ++pos_;
        continue;
      }
      if (peek() != '}') fail("expected ',' or '}'");
    }
    ++pos_;
    skip_space();
    if (pos_ != s_.size()) fail("unexpected text after the dictionary");
    return dict;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw FlowFileError(Kind::malformed, path_,
                        "cannot parse the .npy header at character " + std::to_string(pos_) + ": " + what +
                            " (header: " + std::string(s_) + ")");
  }
  char peek() const { return pos_ < s_.size() ? s_[pos_] : '\0'; }
  void skip_space() {
    while (pos_ < s_.size() && (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) {
      ++pos_;
    }
  }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++pos_;
  }
  std::string parse_string() {
    const char quote = peek();
    if (quote != '\'' && quote != '"') fail("expected a quoted string");
    const std::size_t end = s_.find(quote, pos_ + 1);
    if (end == std::string_view::npos) fail("unterminated string");
    std::string out(s_.substr(pos_ + 1, end - pos_ - 1));
    pos_ = end + 1;
    return out;
  }
  std::int64_t parse_int() {
    if (peek() < '0' || peek() > '9') fail("expected a non-negative integer");
    std::int64_t value = 0;
    while (peek() >= '0' && peek() <= '9') {
      value = value * 10 + (peek() - '0');
      // Far beyond any acceptable dimension; stopping here keeps the arithmetic in range.
      if (value > (std::int64_t{1} << 40)) fail("dimension too large");
      ++pos_;
    }
    if (peek() == 'L') ++pos_;
    return value;
  }
  HeaderValue parse_value() {
    if (peek() == '\'' || peek() == '"') return parse_string();
    if (s_.substr(pos_, 4) == "True") {
      pos_ += 4;
      return true;
    }
    if (s_.substr(pos_, 5) == "False") {
      pos_ += 5;
      return false;
    }
    if (peek() == '(') {
      ++pos_;
      Shape shape;
      while (true) {
        skip_space();
        if (peek() == ')') break;
        shape.push_back(parse_int());
        skip_space();
        if (peek() == ',') {
          ++pos_;
        } else if (peek() != ')') {
          fail("expected ',' or ')' in the shape");
        }
      }
      ++pos_;
      return shape;
    }
    fail("expected a string, True/False or a tuple");
  }

  std::string_view s_;
  const std::filesystem::path& path_;
  std::size_t pos_ = 0;
};

std::string shape_text(const Shape& shape) {
  std::string out = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    out += std::to_string(shape[i]);
    if (i + 1 < shape.size() || shape.size() == 1) out += ", ";
  }
  if (shape.size() == 1) out.pop_back();
  return out + ")";
}

std::string describe_dtype(const std::string& descr) {
  static const std::map<std::string, std::string, std::less<>> names = {{"<f8", "float64"},
                                                                        {">f8", "big-endian float64"},
                                                                        {">f4", "big-endian float32"},
                                                                        {"<f2", "float16"},
                                                                        {"<i4", "int32"},
                                                                        {"<i8", "int64"},
                                                                        {"|u1", "uint8"},
                                                                        {"<u2", "uint16"},
                                                                        {"|b1", "bool"}};
  const auto it = names.find(descr);
  return "'" + descr + "'" + (it != names.end() ? " (" + it->second + ")" : std::string());
}

template <class T>
const T& require_key(const std::map<std::string, HeaderValue>& dict, const char* key, const char* type_name,
                     const std::filesystem::path& path) {
  const auto it = dict.find(key);
  if (it == dict.end()) {
    throw FlowFileError(Kind::malformed, path, std::string(".npy header has no '") + key + "'");
  }
  const T* value = std::get_if<T>(&it->second);
  if (value == nullptr) {
    throw FlowFileError(Kind::malformed, path, std::string(".npy header entry '") + key + "' is not " + type_name);
  }
  return *value;
}

void mark_non_finite_pixels(FlowField& field) {
  const std::size_t n = field.pixel_count();
  for (std::size_t i = 0; i < n; ++i) {
    float& u = field.uv[2 * i];
    float& v = field.uv[2 * i + 1];
    if (std::isfinite(u) && std::isfinite(v)) continue;
    if (field.valid.empty()) field.valid.assign(n, 1);
    field.valid[i] = 0;
    u = 0.f;
    v = 0.f;
  }
}

}  // namespace

NpyArray read_npy_array(const std::filesystem::path& path, const NpyShapeCheck& check_shape) {
  detail::BinaryInput in(path);
  std::array<std::byte, 12> prefix{};
  if (in.size() < 10) {
    throw FlowFileError(Kind::malformed, path,
                        "truncated: " + std::to_string(in.size()) + " bytes, too short for an .npy header");
  }
  in.read(std::span(prefix).first(10), "header prefix");
  if (std::memcmp(prefix.data(), kMagic, sizeof kMagic) != 0) {
    throw FlowFileError(Kind::malformed, path, "not a NumPy .npy file: wrong magic");
  }
  const int major = std::to_integer<int>(prefix[6]);
  const int minor = std::to_integer<int>(prefix[7]);
  if (minor != 0 || major < 1 || major > 3) {
    throw FlowFileError(Kind::malformed, path,
                        "unsupported .npy format version " + std::to_string(major) + "." + std::to_string(minor) +
                            " (supported: 1.0, 2.0, 3.0)");
  }
  std::uint64_t prefix_len = 10;
  std::uint32_t header_len = detail::load_le_u16(prefix.data() + 8);
  if (major >= 2) {  // the length is a 4-byte field there
    in.read(std::span(prefix).subspan(10, 2), "header prefix");
    header_len = detail::load_le_u32(prefix.data() + 8);
    prefix_len = 12;
  }
  if (header_len > kMaxHeaderBytes || prefix_len + header_len > in.size()) {
    throw FlowFileError(Kind::malformed, path,
                        "implausible .npy header length " + std::to_string(header_len) + " for a file of " +
                            std::to_string(in.size()) + " bytes");
  }
  std::string header(header_len, '\0');
  in.read(std::as_writable_bytes(std::span(header)), "header");

  const auto dict = HeaderParser(header, path).parse();
  if (dict.size() != 3) {
    throw FlowFileError(Kind::malformed, path, ".npy header must have exactly the keys descr, fortran_order and shape");
  }
  const auto& descr = require_key<std::string>(dict, "descr", "a string", path);
  const bool fortran = require_key<bool>(dict, "fortran_order", "True/False", path);
  const auto& shape = require_key<Shape>(dict, "shape", "a tuple", path);

  if (descr != "<f4") {
    throw FlowFileError(Kind::malformed, path,
                        "dtype " + describe_dtype(descr) +
                            " is not supported; expected little-endian float32 ('<f4'), e.g. "
                            "np.save(path, array.astype(np.float32))");
  }
  if (check_shape) check_shape(shape);
  if (fortran) {
    throw FlowFileError(Kind::malformed, path,
                        "Fortran-order arrays are not supported; save "
                        "np.ascontiguousarray(array) instead");
  }
  // The element count, bounded by what the file can hold, before anything is allocated.
  const std::uint64_t data_bytes = in.size() - prefix_len - header_len;
  std::uint64_t count = 1;
  bool too_large = false;
  for (const std::int64_t d : shape) {
    if (d < 0 || (d > 0 && count > (data_bytes / 4 + 1) / static_cast<std::uint64_t>(d))) too_large = true;
    count *= static_cast<std::uint64_t>(d < 0 ? 0 : d);
  }
  if (too_large || 4 * count != data_bytes) {
    const bool truncated = too_large || 4 * count > data_bytes;
    throw FlowFileError(Kind::malformed, path,
                        std::string(truncated ? "truncated" : "trailing data") + ": shape " + shape_text(shape) +
                            " needs " +
                            (too_large ? std::string("more bytes than the file has")
                                       : std::to_string(prefix_len + header_len + 4 * count) + " bytes") +
                            ", but the file is " + std::to_string(in.size()) + " bytes");
  }

  NpyArray array{shape, std::vector<float>(count)};
  in.read(std::as_writable_bytes(std::span(array.data)), "array data");
  if constexpr (std::endian::native == std::endian::big) {
    for (float& x : array.data) x = detail::load_le_f32(reinterpret_cast<const std::byte*>(&x));
  }
  return array;
}

FlowField read_npy(const std::filesystem::path& path) {
  NpyArray array = read_npy_array(path, [&](const Shape& shape) {
    if (shape.size() != 3 || shape[2] != 2) {
      throw FlowFileError(
          Kind::malformed, path,
          "array shape " + shape_text(shape) + " is not a flow field; expected (H, W, 2) with u, v last");
    }
    if (!flow_size_acceptable(shape[1], shape[0])) {
      throw FlowFileError(Kind::malformed, path,
                          "implausible flow size " + std::to_string(shape[1]) + "x" + std::to_string(shape[0]) +
                              " (accepted: 1.." + std::to_string(kMaxFlowSide) + " per side, at most " +
                              std::to_string(kMaxFlowPixels) + " pixels)");
    }
  });
  FlowField field;
  field.height = static_cast<int>(array.shape[0]);
  field.width = static_cast<int>(array.shape[1]);
  field.uv = std::move(array.data);
  mark_non_finite_pixels(field);
  return field;
}

void write_npy(const FlowField& field, const std::filesystem::path& path) {
  detail::check_field(field, "write_npy " + path.string());
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(field.height) + ", " +
                       std::to_string(field.width) + ", 2), }";
  // Same rule as numpy's _wrap_header: 1..64 spaces, then '\n', so the data starts aligned.
  const std::size_t unpadded = sizeof kMagic + 2 + 2 + header.size() + 1;
  header.append(kAlign - unpadded % kAlign, ' ');
  header.push_back('\n');

  const std::size_t n = field.pixel_count();
  std::vector<std::byte> bytes(sizeof kMagic + 4 + header.size() + 8 * n);
  std::memcpy(bytes.data(), kMagic, sizeof kMagic);
  bytes[6] = std::byte{1};
  bytes[7] = std::byte{0};
  detail::store_le_u16(bytes.data() + 8, static_cast<std::uint16_t>(header.size()));
  std::memcpy(bytes.data() + 10, header.data(), header.size());
  std::byte* out = bytes.data() + 10 + header.size();
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < n; ++i, out += 8) {
    const bool valid = field.valid.empty() || field.valid[i] != 0;
    detail::store_le_f32(out, valid ? field.uv[2 * i] : kNaN);
    detail::store_le_f32(out + 4, valid ? field.uv[2 * i + 1] : kNaN);
  }
  detail::write_file_atomically(path, bytes);
}

}  // namespace neuflow::flow
