// `neuflow eval`: accuracy on the standard benchmarks (MPI-Sintel, KITTI-2015, Middlebury,
// FlyingChairs), scored the way the NeuFlow-V2 paper and its reference evaluation report it.
// The work is in neuflow::eval (tools/neuflow/eval); this file is the command line.
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "commands.hpp"
#include "common/model_path.hpp"
#include "common/session_options.hpp"
#include "neuflow/eval/errors.hpp"
#include "neuflow/eval/evaluate.hpp"
#include "neuflow/eval/layouts.hpp"
#include "neuflow/eval/model_predictor.hpp"
#include "neuflow/eval/pair_figure.hpp"
#include "neuflow/eval/prediction_files.hpp"
#include "neuflow/eval/report.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"

namespace neuflow::cli {

namespace {

struct EvalArgs {
  std::string dataset, root, model, predictions, json;
  std::string pass = "both";
  bool per_sequence = false;
  std::size_t max_pairs = 0;
  std::string save_viz;  // --save-viz DIR
  std::string plot;      // --plot FILE.svg
  SessionArgs session;
};

constexpr const char* kFooter =
    "Layouts (ROOT is the dataset folder; for Sintel and KITTI also its training/ folder, for\n"
    "FlyingChairs also its data/ folder):\n"
    "  sintel      training/{clean,final}/<scene>/frame_NNNN.png, training/flow/<scene>/frame_NNNN.flo\n"
    "              (each .flo: its frame and the next one)\n"
    "  kitti       training/image_2/NNNNNN_10.png, NNNNNN_11.png, training/flow_occ/NNNNNN_10.png\n"
    "  middlebury  other-data/<seq>/frame10.png, frame11.png, other-gt-flow/<seq>/flow10.flo\n"
    "  chairs      data/NNNNN_img1.ppm, NNNNN_img2.ppm, NNNNN_flow.flo; with FlyingChairs_train_val.txt\n"
    "              beside data/, only the validation pairs (label 2)\n"
    "Padding as the reference evaluation (RAFT/NeuFlow-V2 InputPadder): edge replication to\n"
    "multiples of 16, centred for Sintel, Middlebury and FlyingChairs, at the bottom (and centred\n"
    "across) for KITTI; the flow is cropped back before scoring.\n"
    "Aggregation as the reference: Sintel, Middlebury, FlyingChairs: EPE and <1/3/5 px over all\n"
    "valid pixels of all pairs together; KITTI: EPE = mean of the per-image EPEs over valid\n"
    "pixels, Fl-all (error > 3 px and > 5% of |gt|) and <1/3/5 px over all valid pixels together.\n"
    "Per sequence: Sintel scenes, Middlebury sequences, single pairs for KITTI and FlyingChairs.\n"
    "--predictions DIR: one flow file per pair at DIR/<first image's path relative to the layout\n"
    "root (training/ for Sintel and KITTI, data/ for FlyingChairs), extension replaced by .flo,\n"
    ".png (KITTI 16-bit) or .npy>, e.g. DIR/clean/alley_1/frame_0001.flo, DIR/image_2/000000_10.png,\n"
    "DIR/other-data/RubberWhale/frame10.flo, DIR/00001_img1.flo.\n"
    "Flows from `neuflow convert` score as `eval -m` does only when padded as above: convert pads\n"
    "centred by default; for KITTI give it --padding bottom (and no --model-width/--model-height).\n"
    "Progress goes to stderr, the table to stdout (to stderr with --json -).\n"
    "Exit status: 66 missing dataset, image, ground truth, prediction or model; 65 malformed\n"
    "input (undecodable, sizes that disagree); 73 JSON not writable; 1 otherwise.";

// Reports on stderr after a set's last pair and otherwise at most every few seconds, so a
// long model run shows it is alive without flooding the log.
class ProgressPrinter {
 public:
  void operator()(const eval::EvalProgress& p) {
    if (p.done == 1) last_ = 0;
    if (p.done != p.total && p.elapsed_seconds - last_ < 5.0) return;
    last_ = p.elapsed_seconds;
    std::fprintf(stderr, "eval: %s %zu/%zu pairs, EPE %.3f so far, %.2f s/pair\n", p.set.name.c_str(), p.done, p.total,
                 p.so_far.epe, p.elapsed_seconds / static_cast<double>(p.done));
  }

 private:
  double last_ = 0;  // elapsed seconds at the last line
};

eval::FlowSource make_source(const EvalArgs& a) {
  if (!a.predictions.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(a.predictions, ec)) {
      throw CommandError(kExitNoInput, "eval: " + a.predictions + ": no such predictions folder");
    }
    return eval::PredictionReader(a.predictions);
  }
  std::shared_ptr<const model::FlowModel> model;
  try {
    model = model::FlowModel::load(a.model);
  } catch (const model::CheckpointError& e) {
    throw CommandError(exit_code_for(e), std::string("eval: ") + e.what());
  }
  const model::SessionOptions options = session_options(a.session);
  // FlowSource is copyable and FlowSession is not: share one predictor.
  auto predictor = std::make_shared<eval::ModelPredictor>(std::move(model), options);
  announce_backend(predictor->session(), "eval");
  return [predictor](const eval::EvalSet& set, const eval::Pair& pair) { return (*predictor)(set, pair); };
}

void write_json(const std::string& path, const std::string& text) {
  if (path == "-") {
    std::fputs(text.c_str(), stdout);
    return;
  }
  // Through a temporary sibling, so a script never reads half a result.
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out << text;
    out.close();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(temporary, ec);
      throw CommandError(kExitCantCreate, "eval: " + path + ": cannot write the JSON results");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    throw CommandError(kExitCantCreate, "eval: " + path + ": cannot write the JSON results (" + ec.message() + ")");
  }
}

void run(const EvalArgs& a) {
  const auto dataset = eval::parse_dataset(a.dataset);
  if (!dataset) throw CommandError(kExitUsage, "eval: unknown dataset '" + a.dataset + "'");
  eval::LayoutOptions layout;
  layout.sintel_pass = a.pass == "clean"   ? eval::SintelPass::clean
                       : a.pass == "final" ? eval::SintelPass::final
                                           : eval::SintelPass::both;
  const std::vector<eval::EvalSet> sets = eval::discover_sets(*dataset, a.root, layout);
  const eval::FlowSource source = make_source(a);

  eval::EvaluateOptions options;
  options.max_pairs = a.max_pairs;
  options.progress = ProgressPrinter();
  if (!a.save_viz.empty()) {
    const std::filesystem::path dir = a.save_viz;
    options.on_pair = [dir](const eval::EvalSet& set, const eval::Pair& pair, const flow::FlowField& predicted,
                            const flow::FlowField& ground_truth) {
      // DIR/<set>/<pair key>.png: the key is the first image's path in the layout.
      const std::filesystem::path file = dir / set.name / (pair.key + ".png");
      std::error_code ec;
      std::filesystem::create_directories(file.parent_path(), ec);
      if (ec) throw CommandError(kExitCantCreate, "eval: " + file.parent_path().string() + ": " + ec.message());
      try {
        eval::write_pair_figure(predicted, ground_truth, file);
      } catch (const flow::FlowFileError& e) {
        throw CommandError(kExitCantCreate, std::string("eval: --save-viz: ") + e.what());
      }
    };
  }
  std::vector<eval::SetResult> results;
  results.reserve(sets.size());
  for (const auto& set : sets) results.push_back(eval::evaluate_set(set, source, options));

  const std::string table = eval::format_table(results, a.per_sequence);
  std::fputs(table.c_str(), a.json == "-" ? stderr : stdout);
  if (!a.json.empty()) {
    eval::RunDescription run;
    run.dataset = *dataset;
    run.root = std::filesystem::absolute(a.root);
    if (!a.model.empty()) run.model = std::filesystem::absolute(a.model);
    if (!a.predictions.empty()) run.predictions = std::filesystem::absolute(a.predictions);
    const model::SessionOptions session = session_options(a.session);
    run.iterations = session.iterations;
    run.network_order = session.network_order;
    run.max_pairs = a.max_pairs;
    write_json(a.json, eval::format_json(run, results, a.per_sequence));
  }
  if (!a.plot.empty()) {
    try {
      eval::write_epe_plot(results, a.plot);
    } catch (const std::runtime_error& e) {
      throw CommandError(kExitCantCreate, std::string("eval: --plot: ") + e.what());
    }
  }
}

void run_mapping_errors(const EvalArgs& a) {
  try {
    run(a);
  } catch (const eval::EvalError& e) {
    throw CommandError(e.kind() == eval::EvalError::Kind::missing_input ? kExitNoInput : kExitDataError,
                       std::string("eval: ") + e.what());
  } catch (const flow::FlowFileError& e) {
    throw CommandError(exit_code_for(e), std::string("eval: ") + e.what());
  }
}

}  // namespace

void register_eval(CLI::App& app) {
  auto a = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand(
      "eval", "Accuracy on MPI-Sintel, KITTI-2015, Middlebury or FlyingChairs as the paper reports it");
  cmd->footer(kFooter);
  cmd->add_option("--dataset,-d", a->dataset, "Benchmark layout under ROOT")
      ->required()
      ->check(CLI::IsMember({"sintel", "kitti", "middlebury", "chairs"}));
  cmd->add_option("ROOT", a->root, "The dataset's folder")->required();
  auto* source = cmd->add_option_group("source", "What to score (at most one; default: the model)");
  source->add_option("--model,-m", a->model, std::string(kModelOptionHelp) + "; run on every pair");
  auto* predictions = source->add_option("--predictions", a->predictions,
                                         "Score precomputed flow files from this folder instead (naming below)");
  source->require_option(0, 1);
  cmd->add_option("--pass", a->pass, "Sintel passes to evaluate")
      ->capture_default_str()
      ->check(CLI::IsMember({"clean", "final", "both"}));
  cmd->add_option("--json", a->json, "Also write the results as JSON to FILE ('-': stdout)");
  cmd->add_flag("--per-sequence", a->per_sequence, "Break the results down by sequence");
  cmd->add_option("--save-viz", a->save_viz,
                  "Also write one PNG per pair to DIR/<set>/<pair>.png: prediction, ground truth (one colour "
                  "scale: the ground truth's largest vector) and end-point error (white: the pair's largest)");
  cmd->add_option("--plot", a->plot, "Also write a bar chart of the EPE per sequence to FILE (SVG)")
      ->check(CLI::Validator(
          [](std::string& value) {
            return value.size() > 4 && value.substr(value.size() - 4) == ".svg" ? std::string()
                                                                                : "writes SVG: give FILE.svg";
          },
          "FILE.svg"));
  cmd->add_option("--max-pairs", a->max_pairs, "Score only the first N pairs of each set (default: all)")
      ->check(CLI::PositiveNumber);
  // The reference evaluation pads each pair itself, so no model size is offered here.
  add_session_options(*cmd, a->session, ModelSizeOptions::not_offered);
  for (const char* name : {"--iters-s16", "--iters-s8", "--threads", "--channel-order", "--bgr"}) {
    cmd->get_option(name)->excludes(predictions);
  }
  cmd->callback([a] {
    if (a->predictions.empty()) a->model = resolve_model(a->model, "eval");
    run_mapping_errors(*a);
  });
}

}  // namespace neuflow::cli
