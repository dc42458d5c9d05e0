#pragma once
// The sidecar index of one converted input: one row per flow file, naming the two frames it
// was computed from, in the format neuflowsink writes too (neuflow/flow/flow_index.hpp);
// from_source,to_source name the source images (empty for video frames).
#include <filesystem>
#include <string>
#include <vector>

#include "neuflow/flow/flow_index.hpp"

namespace neuflow::cli {

// index: the pair's position in the input, from 0; file: the flow file's name, relative to
// the index.
using IndexRow = flow::FlowIndexRow;

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
