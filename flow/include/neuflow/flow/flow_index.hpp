#pragma once
// The CSV index that lists flow files, one row per file, written in this one format by
// neuflowsink and by `neuflow convert`: index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,
// from_source,to_source. A timestamp that is not known is an empty field, and so is a source
// (the frame's image file, which only convert knows for folders and pairs of images); text
// fields are quoted as RFC 4180 says.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace neuflow::flow {

// The columns of every flow index, and the position of `file` among them.
inline constexpr std::string_view kFlowIndexColumns =
    "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source";
inline constexpr std::size_t kFlowIndexFileColumn = 5;

// One row.
struct FlowIndexRow {
  std::int64_t index = 0;       // the flow file's index
  std::int64_t from_frame = 0;  // the frames the flow goes from and to
  std::int64_t to_frame = 0;
  std::optional<std::int64_t> from_pts_ns, to_pts_ns;  // their timestamps: empty fields when unknown
  std::string file;                                    // the flow file, as the index names it
  std::string from_source, to_source;                  // the frames' image files: empty when there are none
};

// The header line, line break included.
std::string flow_index_header();

// One row, line break included, its text fields quoted as needed.
std::string flow_index_row(const FlowIndexRow& row);

// A CSV field: `s` itself, or quoted (inner quotes doubled) when it holds a separator, a
// quote or a line break (RFC 4180).
std::string csv_field(std::string_view s);

}  // namespace neuflow::flow
