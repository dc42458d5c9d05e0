#pragma once
// `neuflow fetch-model`'s work without the CLI: which checkpoints are published and under
// which pinned hash, and fetching one into place so that the destination either does not
// change or ends up holding exactly the pinned file (never a partial or unverified one).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "fetch_model/http.hpp"

namespace neuflow::cli {

struct PublishedModel {
  std::string_view name;       // what the user types: "mixed"
  std::string_view file;       // the file in the repository root: "neuflow_mixed.pth"
  std::string_view blob_sha1;  // `git hash-object` of that file
};

// Raw files of the official repository's default branch; "<base>/<file>" is a checkpoint.
inline constexpr std::string_view kOfficialBaseUrl =
    "https://raw.githubusercontent.com/neufieldrobotics/NeuFlow_v2/master";

std::span<const PublishedModel> published_models();
const PublishedModel* find_published_model(std::string_view name);

// "<base>/<file>", with any trailing slashes of base dropped.
std::string model_url(std::string_view base_url, std::string_view file);

struct FetchRequest {
  std::string url;
  std::filesystem::path destination;  // the final file; its directory is created if missing
  std::string expected_sha1;          // git blob SHA-1, 40 hex digits (either case)
  bool force = false;                 // download even when the destination already verifies,
                                      // and replace it when it does not
  // Called on the verified temporary file before it is renamed into place; throwing
  // FetchError rejects it (used to check that a file pinned by the user loads as a model).
  std::function<void(const std::filesystem::path&)> accept;
  HttpOptions http;
};

struct FetchResult {
  bool downloaded = false;  // false: the destination was already there and verified
  std::uintmax_t bytes = 0;
  std::string sha1;  // the verified git blob SHA-1, lowercase
};

// Throws FetchError. On any failure the destination is as it was and no temporary file
// remains (short of the process being killed outright).
FetchResult fetch_model(const FetchRequest& request);

}  // namespace neuflow::cli
