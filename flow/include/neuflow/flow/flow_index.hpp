#pragma once
// The CSV index that lists flow files, one row per file, written by neuflowsink and by
// `neuflow convert`: the columns index,from_frame,to_frame,from_pts_ns,to_pts_ns,file, then
// any of the writer's own (convert adds from_source,to_source), so one reader handles both.
// A timestamp that is not known is an empty field; text fields are quoted as RFC 4180 says.
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

namespace neuflow::flow {

// The columns every flow index starts with, and the position of `file` among them.
inline constexpr std::string_view kFlowIndexColumns = "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file";
inline constexpr std::size_t kFlowIndexFileColumn = 5;

// The common fields of one row.
struct FlowIndexRow {
  std::int64_t index = 0;  // the flow file's index
  std::int64_t from_frame = 0;  // the frames the flow goes from and to
  std::int64_t to_frame = 0;
  std::optional<std::int64_t> from_pts_ns, to_pts_ns;  // their timestamps: empty fields when unknown
  std::string file;  // the flow file, as the index names it
};

// The header line, line break included: kFlowIndexColumns, then `extra_columns`.
std::string flow_index_header(std::initializer_list<std::string_view> extra_columns = {});

// One row, line break included: the fields of `row`, then `extra_fields` (quoted as needed).
std::string flow_index_row(const FlowIndexRow& row, std::initializer_list<std::string_view> extra_fields = {});

// A CSV field: `s` itself, or quoted (inner quotes doubled) when it holds a separator, a
// quote or a line break (RFC 4180).
std::string csv_field(std::string_view s);

}  // namespace neuflow::flow
