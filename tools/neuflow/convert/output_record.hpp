#pragma once
// What made the flows of an output folder, kept beside its index as settings.toml: the model
// (its git blob SHA-1, the value `neuflow fetch-model` pins), the iterations, the model size,
// the channel order, the backend, the precision and the flow files' format. --resume compares
// it with the run's own and refuses to mix flows made otherwise.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace neuflow::cli {

struct OutputRecord {
  std::string model_sha1;
  int iters_s16 = 0, iters_s8 = 0;
  int model_width = 0, model_height = 0;  // 0 × 0: each frame's own size, padded
  std::string channel_order, backend, precision, format;
  // --padding: "centred" (also what a record from before the option means) or "bottom".
  std::string padding = "centred";
  bool operator==(const OutputRecord&) const = default;
};

// The file in `folder`.
std::filesystem::path record_path(const std::filesystem::path& folder);

// nullopt when the folder has none (a new folder, or one written before records existed).
// Throws InputError (65) naming the file when it is not a record.
std::optional<OutputRecord> read_record(const std::filesystem::path& folder);

// Replaces the folder's record at once (a temporary file renamed over it), so a reader or a
// parallel shard never sees half of one. Throws InputError (73) naming the file.
void write_record(const std::filesystem::path& folder, const OutputRecord& record);

// What differs, one item each, as the options that set it: "--iters-s8 8 (now 2)".
std::vector<std::string> record_differences(const OutputRecord& was, const OutputRecord& now);

}  // namespace neuflow::cli
