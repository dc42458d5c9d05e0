#include "neuflow/pipeline/output_record.hpp"

#include <toml++/toml.h>

#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <system_error>
#include <type_traits>

#include "neuflow/pipeline/git_blob_hash.hpp"

namespace neuflow::pipeline {

namespace fs = std::filesystem;

namespace {

// Each field once: its key in the file and the option that sets it.
struct Field {
  const char* key;
  const char* option;  // the setting's name, without the command line's "--"
  const char* absent;  // what a record without the key holds (one written before it existed); null: required
  std::function<std::string(const OutputRecord&)> text;
  std::function<void(OutputRecord&, const toml::node&)> read;
  std::function<void(toml::table&, const OutputRecord&)> write;
};

template <typename T>
Field field(const char* key, const char* option, T OutputRecord::*member) {
  Field f{key, option, nullptr, nullptr, nullptr, nullptr};
  f.text = [member](const OutputRecord& r) {
    if constexpr (std::is_same_v<T, int>) {
      return std::to_string(r.*member);
    } else {
      return r.*member;
    }
  };
  f.read = [member, key](OutputRecord& r, const toml::node& n) {
    if constexpr (std::is_same_v<T, int>) {
      const auto v = n.value<std::int64_t>();
      if (!v) throw std::invalid_argument(std::string(key) + " is not a number");
      r.*member = static_cast<int>(*v);
    } else {
      const auto v = n.value<std::string>();
      if (!v) throw std::invalid_argument(std::string(key) + " is not a string");
      r.*member = *v;
    }
  };
  f.write = [member, key](toml::table& t, const OutputRecord& r) {
    if constexpr (std::is_same_v<T, int>) {
      t.insert(key, static_cast<std::int64_t>(r.*member));
    } else {
      t.insert(key, r.*member);
    }
  };
  return f;
}

const std::vector<Field>& fields() {
  static const std::vector<Field> all{
      field("model_sha1", "model (its git blob SHA-1)", &OutputRecord::model_sha1),
      field("iters_s16", "iters-s16", &OutputRecord::iters_s16),
      field("iters_s8", "iters-s8", &OutputRecord::iters_s8),
      field("model_width", "model-width", &OutputRecord::model_width),
      field("model_height", "model-height", &OutputRecord::model_height),
      field("channel_order", "channel-order", &OutputRecord::channel_order),
      field("backend", "backend", &OutputRecord::backend),
      field("precision", "precision", &OutputRecord::precision),
      field("format", "format", &OutputRecord::format),
      [] {
        Field f = field("padding", "padding", &OutputRecord::padding);
        f.absent = "centred";
        return f;
      }(),
  };
  return all;
}

}  // namespace

fs::path record_path(const fs::path& folder) { return folder / "settings.toml"; }

std::optional<OutputRecord> read_record(const fs::path& folder) {
  const fs::path path = record_path(folder);
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  try {
    const toml::table table = toml::parse_file(path.string());
    OutputRecord r;
    for (const Field& f : fields()) {
      const toml::node* n = table.get(f.key);
      if (n) {
        f.read(r, *n);
      } else if (f.absent) {
        f.read(r, toml::value<std::string>(f.absent));
      } else {
        throw std::invalid_argument(std::string("no ") + f.key);
      }
    }
    return r;
  } catch (const toml::parse_error& e) {
    throw OutputRecordError(
        OutputRecordError::Kind::malformed,
        path.string() + ": not a record of the settings a folder was made with: " + std::string(e.description()));
  } catch (const std::invalid_argument& e) {
    throw OutputRecordError(OutputRecordError::Kind::malformed,
                            path.string() + ": not a record of the settings a folder was made with: " + e.what());
  }
}

void write_record(const fs::path& folder, const OutputRecord& record, std::string_view writer) {
  const fs::path path = record_path(folder);
  const fs::path temporary = path.string() + ".partial-" + std::to_string(::getpid());
  bool written = false;
  int error = 0;
  {
    std::ofstream out(temporary);
    out << "# What made the flows in this folder (" << writer
        << "). neuflow convert --resume and neuflowd's files sink\n"
           "# refuse to add flows made with other settings to them.\n";
    toml::table table;
    for (const Field& f : fields()) f.write(table, record);
    out << table << "\n";
    written = static_cast<bool>(out.flush());
    error = errno;
  }
  std::error_code ec;
  if (!written) {
    fs::remove(temporary, ec);
    throw OutputRecordError(
        OutputRecordError::Kind::unwritable,
        path.string() + ": cannot write the folder's record: " + std::strerror(error != 0 ? error : EIO));
  }
  fs::rename(temporary, path, ec);
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(temporary, ec);
    throw OutputRecordError(OutputRecordError::Kind::unwritable,
                            path.string() + ": cannot write the folder's record: " + reason);
  }
}

std::vector<std::string> record_differences(const OutputRecord& was, const OutputRecord& now, std::string_view prefix) {
  std::vector<std::string> out;
  for (const Field& f : fields()) {
    const std::string a = f.text(was), b = f.text(now);
    if (a != b) out.push_back(std::string(prefix) + f.option + " " + a + " (now " + b + ")");
  }
  return out;
}

void claim_folder(const fs::path& folder, const OutputRecord& record, std::string_view writer) {
  std::optional<OutputRecord> existing;
  try {
    existing = read_record(folder);
  } catch (const OutputRecordError& e) {
    throw OutputRecordError(
        e.kind(), std::string(e.what()) + ": move it away (with the flows it describes) or point the sink elsewhere");
  }
  if (const std::optional<OutputRecord>& was = existing) {
    const std::vector<std::string> differences = record_differences(*was, record, "");
    if (!differences.empty()) {
      std::string list;
      for (const auto& d : differences) list += (list.empty() ? "" : ", ") + d;
      throw OutputRecordError(OutputRecordError::Kind::other_settings,
                              folder.string() + " holds flows made with other settings (" + list +
                                  "): point the sink at another folder, or move those flows and " +
                                  record_path(folder).filename().string() + " away");
    }
  }
  write_record(folder, record, writer);
}

std::string model_sha1(const fs::path& model) { return git_blob_sha1_of_file(model); }

}  // namespace neuflow::pipeline
