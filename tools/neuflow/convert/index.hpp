#pragma once
// The sidecar index of one converted input: one row per flow file, naming the two frames it
// was computed from. The first six columns are those of neuflowsink's index
// (index,from_frame,to_frame,from_pts_ns,to_pts_ns,file: neuflow/flow/flow_index.hpp), so one
// reader handles both; two more name the source images: from_source,to_source (empty for
// video frames).
#include <filesystem>
#include <string>
#include <vector>

#include "neuflow/flow/flow_index.hpp"

namespace neuflow::cli {

inline constexpr const char* kIndexFileName = "index.csv";

struct IndexRow {
  // index: the pair's position in the input, from 0; file: the flow file's name, relative
  // to the index.
  flow::FlowIndexRow flow;
  std::string from_source, to_source;
};

// The rows are kept in memory and the file replaced atomically by write(), so a reader
// never sees a half-written index, and after --resume it lists every pair, computed or not.
class FlowIndex {
 public:
  explicit FlowIndex(std::filesystem::path path) : path_(std::move(path)) {}
  void add(IndexRow row) { rows_.push_back(std::move(row)); }
  // Throws InputError (kExitCantCreate) naming the file.
  void write() const;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::vector<IndexRow> rows_;
};

}  // namespace neuflow::cli
