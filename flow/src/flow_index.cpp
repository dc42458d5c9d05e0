#include "neuflow/flow/flow_index.hpp"

namespace neuflow::flow {

namespace {

std::string optional_field(const std::optional<std::int64_t>& value) {
  return value ? std::to_string(*value) : std::string();
}

}  // namespace

std::string flow_index_header() { return std::string(kFlowIndexColumns) + "\n"; }

std::string flow_index_row(const FlowIndexRow& row) {
  return std::to_string(row.index) + "," + std::to_string(row.from_frame) + "," + std::to_string(row.to_frame) + "," +
         optional_field(row.from_pts_ns) + "," + optional_field(row.to_pts_ns) + "," + csv_field(row.file) + "," +
         csv_field(row.from_source) + "," + csv_field(row.to_source) + "\n";
}

std::string csv_field(std::string_view s) {
  if (s.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(s);
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

}  // namespace neuflow::flow
