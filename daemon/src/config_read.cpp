// The top level of the file: [daemon], [metrics], [rtsp] and the list of [[stream]] tables,
// and the rules that span streams.
#include "config_read.hpp"

#include <array>
#include <map>

#include "config_values.hpp"

namespace neuflow::daemon {
namespace {

using Need = TableReader::Need;

constexpr double max_seconds = 86400.0;

DaemonSettings read_daemon(const TableReader& t) {
  static constexpr std::array<std::string_view, 6> keys = {"log-level",         "threads",      "restart-delay-min",
                                                           "restart-delay-max", "stop-timeout", "stall-timeout"};
  static constexpr std::array<std::string_view, 5> levels = {"error", "warning", "notice", "info", "debug"};
  t.allow_only(keys);
  DaemonSettings d;
  if (auto v = t.choice("log-level", levels)) d.log_level = *v;
  if (auto v = t.integer("threads", 0, 1024)) d.threads = static_cast<int>(*v);
  const auto min = t.number("restart-delay-min", 0.0, max_seconds, true);
  const auto max = t.number("restart-delay-max", 0.0, max_seconds, true);
  if (min) d.restart_delay_min = *min;
  if (max) d.restart_delay_max = *max;
  if (d.restart_delay_min > d.restart_delay_max) {
    t.report(max ? "restart-delay-max" : "restart-delay-min",
             "expected restart-delay-min (" + format_number(d.restart_delay_min) + " s) <= restart-delay-max (" +
                 format_number(d.restart_delay_max) + " s)");
  }
  if (auto v = t.number("stop-timeout", 0.0, max_seconds, true)) d.stop_timeout = *v;
  if (auto v = t.number("stall-timeout", 0.0, max_seconds, true)) d.stall_timeout = *v;
  return d;
}

// `listen = "host:port"` of [metrics] and [rtsp]; false when it is malformed.
bool read_listen(const TableReader& t, std::string& address, int& port) {
  const auto text = t.string("listen");
  if (!text) return !t.has("listen");
  std::string error;
  const auto parsed = parse_host_port(*text, error);
  if (!parsed) {
    t.report("listen", "expected " + error + ", got \"" + *text + "\"");
    return false;
  }
  address = parsed->host;
  port = parsed->port;
  return true;
}

bool same_listener(const std::string& a, const std::string& b) {
  const auto any = [](const std::string& host) { return host == "0.0.0.0" || host == "::"; };
  return a == b || any(a) || any(b);
}

}  // namespace

bool UniqueValues::claim(const std::string& kind, const std::string& value, const std::string& user,
                         SourcePosition where, Issues& issues) {
  const auto [it, inserted] = claims_.try_emplace({kind, value}, Claim{user, where});
  if (inserted) return true;
  issues.add(where, kind + " \"" + value + "\" is already used by " + it->second.user + " (line " +
                        std::to_string(it->second.where.line) + "); each must be unique in the file");
  return false;
}

void ReadContext::need_elements(const std::vector<std::string>& factories, const std::string& user,
                                SourcePosition where) {
  for (const auto& factory : factories) needs.elements.push_back({factory, user, where});
}

std::filesystem::path ReadContext::need_path(PathNeed::Kind kind, const std::string& written, const std::string& key,
                                             SourcePosition where) {
  auto path = resolve_path(folder, written);
  needs.paths.push_back({kind, path, written, key, where});
  return path;
}

ReadResult read_config(const toml::table& root_table, const std::filesystem::path& file, Issues& issues) {
  ReadResult result;
  Config& config = result.config;
  std::error_code ec;
  config.file = std::filesystem::absolute(file, ec);
  if (ec) config.file = file;
  ReadContext context{config.file.parent_path(), issues, result.needs};

  const TableReader root(root_table, "the file's top level", issues);
  static constexpr std::array<std::string_view, 4> keys = {"daemon", "metrics", "rtsp", "stream"};
  root.allow_only(keys);

  if (const auto* t = root.table("daemon", Need::optional))
    config.daemon = read_daemon(TableReader(*t, "[daemon]", issues));
  if (const auto* t = root.table("metrics", Need::optional)) {
    MetricsSettings m;
    const TableReader reader(*t, "[metrics]", issues);
    static constexpr std::array<std::string_view, 1> metrics_keys = {"listen"};
    reader.allow_only(metrics_keys);
    if (read_listen(reader, m.address, m.port)) config.metrics = m;
  }
  if (const auto* t = root.table("rtsp", Need::optional)) {
    RtspSettings r;
    const TableReader reader(*t, "[rtsp]", issues);
    static constexpr std::array<std::string_view, 3> rtsp_keys = {"listen", "credentials", "auth"};
    static constexpr std::array<std::string_view, 2> auth_methods = {"digest", "basic"};
    reader.allow_only(rtsp_keys);
    bool valid = read_listen(reader, r.address, r.port);
    if (auto users = reader.string("credentials")) {
      r.credentials =
          context.need_path(PathNeed::Kind::readable_file, *users, "credentials", reader.position("credentials"));
    } else if (reader.has("credentials")) {
      valid = false;
    }
    if (auto method = reader.choice("auth", auth_methods)) {
      r.auth = *method;
      if (r.credentials.empty()) reader.report("auth", "needs credentials = \"FILE\" (user:password lines) beside it");
    } else if (reader.has("auth")) {
      valid = false;
    }
    if (valid) config.rtsp = r;
    // A malformed [rtsp] still counts as present, so its video sinks are not reported too.
    context.has_rtsp_server = true;
    if (config.rtsp && config.metrics && config.rtsp->port == config.metrics->port &&
        same_listener(config.rtsp->address, config.metrics->address)) {
      reader.report("listen", "the RTSP server and the metrics endpoint cannot both listen on port " +
                                  std::to_string(config.rtsp->port));
    }
  }

  const auto* streams = root.table_array("stream", Need::required,
                                         "at least one [[stream]] table, each with a source, a flow and a sink");
  if (streams && streams->empty()) {
    root.report("stream", "expected at least one [[stream]] table, each with a source, a flow and a sink");
  }
  std::map<std::string, SourcePosition> names;
  if (streams) {
    for (std::size_t i = 0; i < streams->size(); ++i) {
      const TableReader stream(*streams->get(i)->as_table(), "[[stream]]", issues);
      StreamConfig s = read_stream(stream, i, context);
      if (!s.name.empty()) {
        const auto [it, inserted] = names.try_emplace(s.name, stream.position("name"));
        if (!inserted) {
          stream.report("name", "stream \"" + s.name + "\" is already defined at line " +
                                    std::to_string(it->second.line) + "; stream names must be unique");
        }
      }
      config.streams.push_back(std::move(s));
    }
  }
  return result;
}

}  // namespace neuflow::daemon
