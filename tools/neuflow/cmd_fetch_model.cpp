// `neuflow fetch-model NAME`: download a published NeuFlow-V2 checkpoint and verify it
// against its pinned git blob SHA-1 before it appears under its final name.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "commands.hpp"
#include "fetch_model/error.hpp"
#include "fetch_model/fetch.hpp"
#include "fetch_model/hash.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"

namespace neuflow::cli {

namespace {

constexpr int kExitUnavailable = 69;   // EX_UNAVAILABLE: the server could not be reached or failed
constexpr int kExitInterrupted = 130;  // what a shell reports for a job stopped by Ctrl-C

struct FetchModelArgs {
  std::string name;
  std::string output_dir = "models";
  std::string base_url{kOfficialBaseUrl};
  std::string sha1;
  bool force = false;
  long connect_timeout_s = 30;
  long stall_timeout_s = 60;
};

int fetch_exit_code(const FetchError& e) {
  switch (e.kind()) {
    case FetchError::Kind::kUnavailable: return kExitUnavailable;
    case FetchError::Kind::kIntegrity: return kExitDataError;
    case FetchError::Kind::kLocalIo: return kExitCantCreate;
    case FetchError::Kind::kInterrupted: return kExitInterrupted;
  }
  return kExitFailure;
}

void run_fetch_model(const FetchModelArgs& a) {
  const PublishedModel* model = find_published_model(a.name);
  if (!model) throw CommandError(kExitUsage, "fetch-model: unknown model '" + a.name + "'");

  FetchRequest request;
  request.url = model_url(a.base_url, model->file);
  request.destination = std::filesystem::path(a.output_dir) / model->file;
  request.expected_sha1 = a.sha1.empty() ? std::string(model->blob_sha1) : a.sha1;
  request.force = a.force;
  request.http.connect_timeout_s = a.connect_timeout_s;
  request.http.stall_timeout_s = a.stall_timeout_s;
  if (::isatty(STDERR_FILENO)) request.http.progress_label = std::string(model->file);
  // The official pin identifies the published file exactly. A hash the user supplies only
  // says the bytes are the ones they meant, so also check those bytes are a model we can run
  // before putting them where the quick start and `neuflow flow` will pick them up.
  if (!a.sha1.empty()) {
    request.accept = [url = request.url](const std::filesystem::path& file) {
      try {
        model::FlowModel::load(file);
      } catch (const model::CheckpointError& e) {
        throw FetchError(FetchError::Kind::kIntegrity,
                         url + " matches --sha1 but is not a NeuFlow-V2 checkpoint, so nothing was saved: " + e.what());
      }
    };
  }

  FetchResult result;
  try {
    result = fetch_model(request);
  } catch (const FetchError& e) {
    std::string message = "fetch-model: " + std::string(e.what());
    // Offline machines and blocked networks have the manual way.
    if (e.kind() == FetchError::Kind::kUnavailable || e.kind() == FetchError::Kind::kInterrupted) {
      message += "\n  the file can also be copied by hand: get " + std::string(model->file) +
                 " from the NeuFlow-V2 repository (github.com/neufieldrobotics/NeuFlow_v2) and put it at " +
                 request.destination.string() + "; `neuflow fetch-model " + a.name + "` then only verifies it";
    }
    throw CommandError(fetch_exit_code(e), message);
  }
  if (result.downloaded) {
    std::fprintf(stderr, "%s: downloaded %.1f MB from %s, git blob SHA-1 %s verified\n", request.destination.c_str(),
                 static_cast<double>(result.bytes) * 1e-6, request.url.c_str(), result.sha1.c_str());
  } else {
    std::fprintf(stderr,
                 "%s: already there and verified (git blob SHA-1 %s); nothing downloaded (--force fetches it again)\n",
                 request.destination.c_str(), result.sha1.c_str());
  }
  std::printf("%s\n", request.destination.c_str());
}

}  // namespace

void register_fetch_model(CLI::App& app) {
  auto args = std::make_shared<FetchModelArgs>();
  auto* sub = app.add_subcommand(
      "fetch-model",
      "Download a published NeuFlow-V2 checkpoint into DIR/neuflow_NAME.pth, verified against its pinned git blob "
      "SHA-1; prints the file's path");
  sub->add_option("NAME", args->name, "mixed (several datasets; for real-world use), things or sintel")
      ->required()
      ->check(CLI::IsMember({"mixed", "things", "sintel"}));
  sub->add_option("--output-dir,-o", args->output_dir, "Directory to put the checkpoint in (created if missing)")
      ->capture_default_str();
  sub->add_option("--base-url", args->base_url, "Where the .pth files are: URL/neuflow_NAME.pth is fetched (a mirror)")
      ->envname("NEUFLOW_MODEL_BASE_URL")
      ->capture_default_str();
  sub->add_option("--sha1", args->sha1,
                  "Expect this git blob SHA-1 (`git hash-object FILE`) instead of the pinned one, e.g. for a mirror "
                  "with its own copy; the file must then also load as a NeuFlow-V2 checkpoint")
      ->check([](const std::string& text) {
        return is_sha1_hex(text) ? std::string()
                                 : "wants 40 hex digits (as `git hash-object FILE` prints), got '" + text + "'";
      });
  sub->add_flag("--force", args->force,
                "Download even if the file is already there, replacing it once the new one verifies");
  sub->add_option("--connect-timeout", args->connect_timeout_s, "Give up connecting after this many seconds")
      ->capture_default_str()
      ->check(CLI::Range(1L, 600L));
  sub->add_option("--stall-timeout", args->stall_timeout_s, "Give up when under 1 KiB/s arrives for this many seconds")
      ->capture_default_str()
      ->check(CLI::Range(1L, 3600L));
  sub->callback([args] { run_fetch_model(*args); });
}

}  // namespace neuflow::cli
