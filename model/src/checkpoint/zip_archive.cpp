#include "checkpoint/zip_archive.hpp"

#include <zip.h>

#include <algorithm>
#include <limits>
#include <system_error>

#include "neuflow/model/checkpoint.hpp"

namespace neuflow::model::detail {

namespace {

using Kind = CheckpointError::Kind;

std::string libzip_message(int code) {
  zip_error_t error;
  zip_error_init_with_code(&error, code);
  std::string message = zip_error_strerror(&error);
  zip_error_fini(&error);
  return message;
}

std::string archive_message(::zip* archive) { return zip_error_strerror(zip_get_error(archive)); }

// Closes a zip_file_t on scope exit.
struct ZipFileCloser {
  zip_file_t* file;
  ~ZipFileCloser() {
    if (file != nullptr) zip_fclose(file);
  }
};

}  // namespace

ZipArchive::ZipArchive(const std::filesystem::path& path) {
  std::error_code ec;
  file_size_ = std::filesystem::file_size(path, ec);
  if (ec) throw CheckpointError(Kind::kIo, "cannot read the file: " + ec.message());

  int code = 0;
  archive_ = zip_open(path.c_str(), ZIP_RDONLY, &code);
  if (archive_ == nullptr) {
    switch (code) {
      case ZIP_ER_NOZIP:
        throw CheckpointError(Kind::kFormat,
                              "not a zip archive (no end-of-central-directory record; the file "
                              "may be truncated)");
      case ZIP_ER_INCONS:
        throw CheckpointError(Kind::kFormat,
                              "inconsistent zip archive (truncated or corrupt): " + libzip_message(code));
      case ZIP_ER_NOENT:
      case ZIP_ER_OPEN:
      case ZIP_ER_READ:
      case ZIP_ER_SEEK: throw CheckpointError(Kind::kIo, "cannot read the file: " + libzip_message(code));
      default: throw CheckpointError(Kind::kFormat, "cannot open the zip archive: " + libzip_message(code));
    }
  }

  const zip_int64_t count = zip_get_num_entries(archive_, 0);
  if (count < 0) {
    zip_discard(archive_);
    throw CheckpointError(Kind::kFormat, "cannot list the zip archive's entries");
  }
  names_.reserve(static_cast<std::size_t>(count));
  for (zip_int64_t i = 0; i < count; ++i) {
    const char* name = zip_get_name(archive_, static_cast<zip_uint64_t>(i), ZIP_FL_ENC_RAW);
    if (name == nullptr) {
      const std::string message = archive_message(archive_);
      zip_discard(archive_);
      throw CheckpointError(Kind::kFormat, "unreadable zip entry name: " + message);
    }
    names_.emplace_back(name);
  }
}

ZipArchive::~ZipArchive() {
  if (archive_ != nullptr) zip_discard(archive_);  // read-only: nothing to write back
}

std::optional<uint64_t> ZipArchive::find(const std::string& name) const {
  const zip_int64_t index = zip_name_locate(archive_, name.c_str(), ZIP_FL_ENC_RAW);
  if (index < 0) return std::nullopt;
  return static_cast<uint64_t>(index);
}

std::optional<uint64_t> ZipArchive::size_of(const std::string& name) const {
  const auto index = find(name);
  if (!index) return std::nullopt;
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(archive_, *index, 0, &st) != 0 || (st.valid & ZIP_STAT_SIZE) == 0) {
    return std::nullopt;
  }
  return st.size;
}

std::vector<unsigned char> ZipArchive::read(const std::string& name, uint64_t max_bytes) const {
  const auto index = find(name);
  if (!index) throw CheckpointError(Kind::kFormat, "zip entry '" + name + "' is missing");
  zip_stat_t st;
  zip_stat_init(&st);
  if (zip_stat_index(archive_, *index, 0, &st) != 0 || (st.valid & ZIP_STAT_SIZE) == 0) {
    throw CheckpointError(Kind::kFormat, "cannot stat zip entry '" + name + "': " + archive_message(archive_));
  }
  if (st.size > max_bytes) {
    throw CheckpointError(Kind::kFormat, "zip entry '" + name + "' is too large (" + std::to_string(st.size) +
                                             " bytes, limit " + std::to_string(max_bytes) + ")");
  }
  const bool stored = (st.valid & ZIP_STAT_COMP_METHOD) != 0 && st.comp_method == ZIP_CM_STORE;
  if (stored && st.size > file_size_) {
    throw CheckpointError(Kind::kFormat, "zip entry '" + name + "' claims " + std::to_string(st.size) +
                                             " bytes, more than the whole file");
  }

  // Deflate expands at most ~1032:1; anything claiming more is a bomb or corrupt.
  if (!stored && (st.valid & ZIP_STAT_COMP_SIZE) != 0 && st.size / 1100 > st.comp_size + (uint64_t{1} << 20)) {
    throw CheckpointError(Kind::kFormat, "zip entry '" + name + "' claims an implausible " + "compression ratio");
  }

  ZipFileCloser file{zip_fopen_index(archive_, *index, 0)};
  if (file.file == nullptr) {
    throw CheckpointError(Kind::kFormat, "cannot open zip entry '" + name + "': " + archive_message(archive_));
  }

  // Stored entries cannot be larger than the file (checked above), so their buffer is
  // allocated at once; compressed ones grow as data actually arrives.
  constexpr uint64_t kChunk = uint64_t{1} << 20;
  std::vector<unsigned char> data;
  data.reserve(static_cast<std::size_t>(stored ? st.size : std::min(st.size, kChunk)));
  while (data.size() < st.size) {
    const uint64_t want = std::min<uint64_t>(st.size - data.size(), kChunk);
    const std::size_t old = data.size();
    data.resize(old + static_cast<std::size_t>(want));
    const zip_int64_t got = zip_fread(file.file, data.data() + old, want);
    if (got < 0) {
      throw CheckpointError(
          Kind::kFormat, "cannot read zip entry '" + name + "': " + zip_error_strerror(zip_file_get_error(file.file)));
    }
    data.resize(old + static_cast<std::size_t>(got));
    if (got == 0) break;
  }
  if (data.size() != st.size) {
    throw CheckpointError(Kind::kFormat, "zip entry '" + name + "' is truncated (" + std::to_string(data.size()) +
                                             " of " + std::to_string(st.size) + " bytes)");
  }
  // One more read reaches the end of the entry, where libzip verifies the CRC.
  unsigned char extra = 0;
  const zip_int64_t tail = zip_fread(file.file, &extra, 1);
  if (tail != 0) {
    throw CheckpointError(Kind::kFormat,
                          "zip entry '" + name + "' is corrupt" +
                              (tail < 0 ? std::string(": ") + zip_error_strerror(zip_file_get_error(file.file))
                                        : std::string(" (longer than its stated size)")));
  }
  return data;
}

}  // namespace neuflow::model::detail
