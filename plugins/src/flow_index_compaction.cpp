#include "flow_index_compaction.hpp"

#include <glib.h>

#include <filesystem>
#include <unordered_map>

#include "neuflow/flow/flow_index.hpp"

namespace neuflow::gst {

namespace {

constexpr std::size_t kFileField = flow::kFlowIndexFileColumn;

std::string read_index(const std::string &path, bool *exists) {
  gchar *contents = nullptr;
  gsize length = 0;
  GError *error = nullptr;
  if (!g_file_get_contents(path.c_str(), &contents, &length, &error)) {
    const bool missing = g_error_matches(error, G_FILE_ERROR, G_FILE_ERROR_NOENT);
    const std::string message = error->message;
    g_error_free(error);
    if (missing && exists) {
      *exists = false;
      return {};
    }
    throw IndexCompactionError("cannot read the flow index: " + message);
  }
  if (exists) *exists = true;
  std::string text(contents, length);
  g_free(contents);
  return text;
}

bool file_exists(const std::filesystem::path &p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

}  // namespace

std::vector<std::string_view> csv_records(std::string_view text) {
  std::vector<std::string_view> records;
  std::size_t start = 0;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      quoted = !quoted;  // "" inside a quoted field toggles twice
    } else if (c == '\n' && !quoted) {
      std::size_t end = i;
      if (end > start && text[end - 1] == '\r') --end;
      records.push_back(text.substr(start, end - start));
      start = i + 1;
    }
  }
  if (start < text.size()) records.push_back(text.substr(start));  // no final line break
  return records;
}

std::vector<std::string> csv_fields(std::string_view record) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < record.size(); ++i) {
    const char c = record[i];
    if (quoted) {
      if (c == '"' && i + 1 < record.size() && record[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

std::size_t count_index_rows(const std::string &path) {
  bool exists = false;
  const std::string text = read_index(path, &exists);
  const std::size_t records = csv_records(text).size();
  return records > 0 ? records - 1 : 0;
}

IndexCompaction compact_flow_index(const std::string &index_path, const std::string &index_dir) {
  bool exists = false;
  const std::string text = read_index(index_path, &exists);
  IndexCompaction result;
  if (!exists) return result;
  const std::vector<std::string_view> records = csv_records(text);
  if (records.empty()) return result;

  // The last row for each file, by its name as written.
  std::vector<std::string> names(records.size());
  std::unordered_map<std::string, std::size_t> last_row;
  for (std::size_t r = 1; r < records.size(); ++r) {
    std::vector<std::string> fields = csv_fields(records[r]);
    if (fields.size() <= kFileField) continue;
    names[r] = std::move(fields[kFileField]);
    last_row[names[r]] = r;
  }

  std::string out(records[0]);
  out += '\n';
  for (std::size_t r = 1; r < records.size(); ++r) {
    bool keep = true;
    if (!names[r].empty()) {
      const std::filesystem::path name(names[r]);
      // A bare name was written for a file beside the index, but a file in the working
      // directory gets one too: keep the row if either exists.
      keep = last_row[names[r]] == r &&
             (file_exists(name) || (!name.has_parent_path() && file_exists(std::filesystem::path(index_dir) / name)));
    }
    if (keep) {
      out.append(records[r]);
      out += '\n';
      ++result.rows_kept;
    } else {
      ++result.rows_dropped;
    }
  }
  if (result.rows_dropped == 0) return result;

  GError *error = nullptr;
  // CONSISTENT: written to a temporary file and renamed over the index, so a reader (or
  // a crash) sees the old index or the new one, never a mix.
  if (!g_file_set_contents_full(index_path.c_str(), out.data(), static_cast<gssize>(out.size()),
                                G_FILE_SET_CONTENTS_CONSISTENT, 0666, &error)) {
    const std::string message = error->message;
    g_error_free(error);
    throw IndexCompactionError("cannot rewrite the flow index: " + message);
  }
  return result;
}

}  // namespace neuflow::gst
