// neuflowsink's index CSV (plugins/src/flow_index_compaction.hpp): the RFC 4180 record and field
// split, and compaction of an index whose rows name files that mostly do not exist.
// IndexCompactionError is the documented failure; the records must lie inside the text, and a
// compaction keeps at most the rows there were.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "flow_index_compaction.hpp"
#include "fuzz_support.hpp"

namespace fs = std::filesystem;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("neuflow-fuzz-index-" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    std::size_t covered = 0;
    for (const std::string_view record : neuflow::gst::csv_records(text)) {
      if (record.data() < text.data() || record.data() + record.size() > text.data() + text.size()) {
        neuflow::fuzz::invariant_failed("flow_index", "a record outside the text");
      }
      covered += record.size();
      (void)neuflow::gst::csv_fields(record);
    }
    if (covered > text.size()) neuflow::fuzz::invariant_failed("flow_index", "records longer than the text");

    const fs::path index = dir / "index.csv";
    std::ofstream(index, std::ios::binary).write(text.data(), static_cast<std::streamsize>(text.size()));
    const std::size_t rows = neuflow::gst::count_index_rows(index.string());
    const auto compaction = neuflow::gst::compact_flow_index(index.string(), dir.string());
    if (compaction.rows_kept > rows) neuflow::fuzz::invariant_failed("flow_index", "more rows kept than there were");
  } catch (const neuflow::gst::IndexCompactionError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("flow_index");
  }
  return 0;
}
