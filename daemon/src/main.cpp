// neuflowd: runs the capture → flow → sink streams of one config file until stopped.
//   neuflowd --config /etc/neuflow/neuflowd.toml    run (under systemd: Type=notify)
//   neuflowd --check-config FILE                    validate and exit
#include <gst/gst.h>

#include <CLI/CLI.hpp>

#include <malloc.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "config.hpp"
#include "daemon.hpp"
#include "log.hpp"

namespace {

constexpr int kExitConfig = 78;  // EX_CONFIG: the unit's RestartPreventExitStatus

// glibc raises its mmap threshold (up to 32 MiB) each time a large block is freed, after which
// large buffers come from the heap arenas; a reload frees and rebuilds a stream's sessions and
// pipeline from other threads, and the arenas keep the freed space. Measured: 100 alternating
// reloads took a daemon from 236 to 416 MB of RSS, for good. With a fixed threshold large
// buffers are mapped and unmapped whole, and RSS after those reloads stays within 2% of a fresh
// start (daemon/README.md, "Memory"). MALLOC_MMAP_THRESHOLD_ in the environment still wins.
void keep_large_allocations_mapped() {
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") != nullptr) return;
  mallopt(M_MMAP_THRESHOLD, 128 * 1024);
}

// One issue as compilers print theirs: the position and message, then the line with a caret.
void print_issue(const neuflow::daemon::ConfigIssue& issue) {
  std::fprintf(stderr, "%s\n", issue.to_string().c_str());
  if (const std::string excerpt = issue.source_excerpt(); !excerpt.empty())
    std::fprintf(stderr, "%s\n", excerpt.c_str());
}

void print_issues(const neuflow::daemon::ConfigError& e) {
  for (const auto& issue : e.issues()) print_issue(issue);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"neuflowd: NeuFlow-V2 optical flow streams (cameras, files, network) to files, shared memory and video"};
  app.set_version_flag("--version", std::string("neuflowd ") + NEUFLOW_VERSION);
  std::string config_file = "/etc/neuflow/neuflowd.toml";
  std::string check_file;
  std::string level;
  app.add_option("-c,--config", config_file, "Config file to run")->capture_default_str();
  app.add_option("--check-config", check_file,
                 "Check FILE and exit: 78 with each error (its line, a caret under the column) when the file itself is "
                 "wrong (syntax, keys, "
                 "types, ranges, names), else 0; what this machine lacks now (a camera, a model, an input file, a "
                 "GStreamer element) is printed as a warning, since the daemon waits for it");
  app.add_option("--log-level", level, "error, warning, notice, info or debug; overrides [daemon] log-level");
  CLI11_PARSE(app, argc, argv);

  using namespace neuflow::daemon;
  keep_large_allocations_mapped();
  use_log_prefix_from_environment();
  gst_init(nullptr, nullptr);

  if (!check_file.empty()) {
    try {
      const Config config = load_config(check_file);
      for (const auto& warning : config.warnings) print_issue(warning);
      std::printf("%s: OK, %zu stream%s", check_file.c_str(), config.streams.size(),
                  config.streams.size() == 1 ? "" : "s");
      if (!config.warnings.empty()) {
        std::printf(" (%zu warning%s: those streams wait, in backoff, until it is fixed)", config.warnings.size(),
                    config.warnings.size() == 1 ? "" : "s");
      }
      std::printf("\n");
      return 0;
    } catch (const ConfigError& e) {
      print_issues(e);
      return kExitConfig;
    }
  }

  try {
    Config config = load_config(config_file);
    if (!level.empty()) config.daemon.log_level = level;
    set_log_level(parse_log_level(config.daemon.log_level));
    Daemon daemon(std::move(config), level);
    return daemon.run();
  } catch (const ConfigError& e) {
    print_issues(e);
    return kExitConfig;
  } catch (const std::exception& e) {
    log_error(e.what());
    return 1;
  }
}
