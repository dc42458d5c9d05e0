#pragma once
// What made the flows of an output folder, kept beside its index as settings.toml: the model
// (its git blob SHA-1, the value `neuflow fetch-model` pins), the iterations, the model size,
// the channel order, the backend, the precision and the flow files' format. `neuflow convert
// --resume` compares it with the run's own and refuses to mix flows made otherwise; neuflowd's
// files sink does the same when its stream starts.
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace neuflow::pipeline {

struct OutputRecord {
  std::string model_sha1;
  int iters_s16 = 0, iters_s8 = 0;
  int model_width = 0, model_height = 0;  // 0 × 0: each frame's own size, padded
  // backend: where `neuflow convert` ran (cpu, vulkan); for neuflowd, the backend setting.
  std::string channel_order, backend, precision, format;
  // --padding: "centred" (also what a record from before the option means) or "bottom".
  std::string padding = "centred";
  bool operator==(const OutputRecord&) const = default;
};

class OutputRecordError : public std::runtime_error {
 public:
  // other_settings: claim_folder found flows made otherwise.
  enum class Kind { malformed, unwritable, other_settings };
  OutputRecordError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// The file in `folder`.
std::filesystem::path record_path(const std::filesystem::path& folder);

// nullopt when the folder has none (a new folder, or one written before records existed).
// Throws OutputRecordError (malformed) naming the file when it is not a record.
std::optional<OutputRecord> read_record(const std::filesystem::path& folder);

// Replaces the folder's record at once (a temporary file renamed over it), so a reader or a
// parallel shard never sees half of one. `writer` names the program in the file's comment.
// Throws OutputRecordError (unwritable) naming the file.
void write_record(const std::filesystem::path& folder, const OutputRecord& record, std::string_view writer);

// What differs, one item each, by the name of the setting that sets it, after `prefix` ("--"
// for the command line's options, "" for the daemon's keys): "--iters-s8 8 (now 2)".
std::vector<std::string> record_differences(const OutputRecord& was, const OutputRecord& now, std::string_view prefix);

// Takes `folder` for flows made as `record` says, as neuflowd's files sink does when its stream
// starts: a folder whose record says its flows were made otherwise is refused
// (OutputRecordError other_settings, naming each difference by the config's key); otherwise
// the record is written. Throws OutputRecordError.
void claim_folder(const std::filesystem::path& folder, const OutputRecord& record, std::string_view writer);

// The model file's git blob SHA-1, as the record holds it. Throws std::runtime_error naming
// the file when it cannot be read.
std::string model_sha1(const std::filesystem::path& model);

}  // namespace neuflow::pipeline
