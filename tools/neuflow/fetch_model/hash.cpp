#include "fetch_model/hash.hpp"

#include <stdexcept>

#include "fetch_model/error.hpp"

namespace neuflow::cli {

std::string git_blob_sha1_of_file(const std::filesystem::path& path) {
  try {
    return pipeline::git_blob_sha1_of_file(path);
  } catch (const std::runtime_error& e) {
    throw FetchError(FetchError::Kind::kLocalIo, e.what());
  }
}

}  // namespace neuflow::cli
