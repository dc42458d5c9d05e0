#pragma once
// Keeps neuflowsink's CSV index (index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source: see
// neuflow/flow/flow_index.hpp) from growing forever when old flow files are deleted: rewrites
// it, atomically, with the rows whose files still exist. No GStreamer in here.
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace neuflow::gst {

class IndexCompactionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The records of CSV text (RFC 4180: a line break inside a quoted field belongs to the
// field), each without its line break.
std::vector<std::string_view> csv_records(std::string_view text);

// The fields of one record, unquoted.
std::vector<std::string> csv_fields(std::string_view record);

// Data rows (records after the header) of the index at `path`; 0 when it does not exist.
// Throws IndexCompactionError when it exists but cannot be read.
std::size_t count_index_rows(const std::string &path);

struct IndexCompaction {
  std::size_t rows_kept = 0;
  std::size_t rows_dropped = 0;
};

// Rewrites the index at `index_path` (temporary file, then rename) keeping the header and
// each row whose file exists, beside the index (`index_dir`) for a bare name or where the
// row names it, unless a later row names the same file (an index reused by a restart: the
// last row describes the file on disk). Rows that do not parse are kept: they are not ours
// to judge. Throws IndexCompactionError naming the file and the reason.
IndexCompaction compact_flow_index(const std::string &index_path, const std::string &index_dir);

}  // namespace neuflow::gst
