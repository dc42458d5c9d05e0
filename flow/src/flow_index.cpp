#include "neuflow/flow/flow_index.hpp"

namespace neuflow::flow {

namespace {

std::string optional_field(const std::optional<std::int64_t>& value) {
  return value ? std::to_string(*value) : std::string();
}

}  // namespace

std::string flow_index_header(std::initializer_list<std::string_view> extra_columns) {
  std::string line(kFlowIndexColumns);
  for (std::string_view column : extra_columns) {
    line += ',';
    line += column;
  }
  return line + "\n";
}

std::string flow_index_row(const FlowIndexRow& row, std::initializer_list<std::string_view> extra_fields) {
  std::string line = std::to_string(row.index) + "," + std::to_string(row.from_frame) + "," +
                     std::to_string(row.to_frame) + "," + optional_field(row.from_pts_ns) + "," +
                     optional_field(row.to_pts_ns) + "," + csv_field(row.file);
  for (std::string_view field : extra_fields) {
    line += ',';
    line += csv_field(field);
  }
  return line + "\n";
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
