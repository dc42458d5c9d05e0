#include "neuflow/eval/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace neuflow::eval {

namespace {

// Table cells: EPE in px with 3 decimals, ratios in % with 2, "n/a" / "inf" where not finite.
std::string cell(double value, bool percent) {
  if (std::isnan(value)) return "n/a";
  if (std::isinf(value)) return "inf";
  char buf[64];
  if (percent) {
    std::snprintf(buf, sizeof buf, "%.2f%%", 100.0 * value);
  } else {
    std::snprintf(buf, sizeof buf, "%.3f", value);
  }
  return buf;
}

std::string pad_left(const std::string& s, std::size_t width) {
  return s.size() >= width ? s : std::string(width - s.size(), ' ') + s;
}
std::string pad_right(const std::string& s, std::size_t width) {
  return s.size() >= width ? s : s + std::string(width - s.size(), ' ');
}

std::string table_row(const std::string& name, std::size_t name_width, const Summary& s, bool with_fl) {
  std::string row =
      pad_right(name, name_width) + pad_left(std::to_string(s.pairs), 7) + pad_left(cell(s.epe, false), 10);
  if (with_fl) row += pad_left(cell(s.fl_all, true), 9);
  for (double rate : {s.within_1px, s.within_3px, s.within_5px}) row += pad_left(cell(rate, true), 9);
  return row + "\n";
}

// JSON has no NaN or infinity: null says "not available".
std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string json_summary_fields(const Summary& s) {
  return "\"pairs\": " + std::to_string(s.pairs) + ", \"valid_pixels\": " + std::to_string(s.valid_pixels) +
         ", \"epe\": " + json_number(s.epe) + ", \"fl_all\": " + json_number(s.fl_all) +
         ", \"within_1px\": " + json_number(s.within_1px) + ", \"within_3px\": " + json_number(s.within_3px) +
         ", \"within_5px\": " + json_number(s.within_5px);
}

}  // namespace

std::string format_table(const std::vector<SetResult>& results, bool per_sequence) {
  const bool with_fl =
      std::any_of(results.begin(), results.end(), [](const SetResult& r) { return r.dataset == Dataset::kitti; });
  std::size_t name_width = 4;
  for (const auto& r : results) {
    name_width = std::max(name_width, r.name.size());
    if (per_sequence) {
      for (const auto& s : r.sequences) name_width = std::max(name_width, s.name.size() + 2);
    }
  }
  name_width += 2;
  std::string out = pad_right("set", name_width) + pad_left("pairs", 7) + pad_left("EPE", 10);
  if (with_fl) out += pad_left("Fl-all", 9);
  out += pad_left("<1px", 9) + pad_left("<3px", 9) + pad_left("<5px", 9) + "\n";
  for (const auto& r : results) {
    out += table_row(r.name, name_width, r.summary, with_fl);
    if (per_sequence) {
      for (const auto& s : r.sequences) out += table_row("  " + s.name, name_width, s.summary, with_fl);
    }
  }
  return out;
}

std::string format_json(const RunDescription& run, const std::vector<SetResult>& results, bool per_sequence) {
  std::string out = "{\"dataset\": " + json_string(std::string(to_string(run.dataset))) +
                    ", \"root\": " + json_string(run.root.string());
  if (run.model.empty()) {
    out += ", \"source\": \"predictions\", \"predictions\": " + json_string(run.predictions.string());
  } else {
    out += ", \"source\": \"model\", \"model\": " + json_string(run.model.string()) +
           ", \"iters_s16\": " + std::to_string(run.iterations.s16) +
           ", \"iters_s8\": " + std::to_string(run.iterations.s8) + ", \"channel_order\": \"" +
           std::string(model::channel_order_name(run.network_order)) + "\"";
  }
  out += ", \"max_pairs\": " + (run.max_pairs == 0 ? std::string("null") : std::to_string(run.max_pairs));
  out += ",\n \"results\": [";
  for (std::size_t i = 0; i < results.size(); ++i) {
    const SetResult& r = results[i];
    out += std::string(i ? ",\n  " : "\n  ") + "{\"set\": " + json_string(r.name) + ", " +
           json_summary_fields(r.summary) +
           ", \"epe_aggregation\": " + (r.aggregation == Aggregation::mean_of_images ? "\"images\"" : "\"pixels\"");
    if (per_sequence) {
      out += ", \"sequences\": [";
      for (std::size_t s = 0; s < r.sequences.size(); ++s) {
        out += std::string(s ? ",\n    " : "\n    ") + "{\"sequence\": " + json_string(r.sequences[s].name) + ", " +
               json_summary_fields(r.sequences[s].summary) + "}";
      }
      out += "]";
    }
    out += "}";
  }
  return out + "]}\n";
}

}  // namespace neuflow::eval
