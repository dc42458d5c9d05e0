#pragma once
// The git blob SHA-1 (neuflow/pipeline/git_blob_hash.hpp) as fetch-model uses it: its errors
// are FetchError, so that they map to fetch-model's exit codes.
#include <filesystem>
#include <string>

#include "neuflow/pipeline/git_blob_hash.hpp"

namespace neuflow::cli {

using pipeline::GitBlobHasher;
using pipeline::is_sha1_hex;

// The git blob SHA-1 of a file on disk. Throws FetchError (kLocalIo) naming the file.
std::string git_blob_sha1_of_file(const std::filesystem::path& path);

}  // namespace neuflow::cli
