// The terminal table and the JSON for scripts: the JSON is checked by Python's own parser,
// with the keys and values a script would read.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string>

#include "layout_fixtures.hpp"
#include "neuflow/eval/report.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::eval {
namespace {

SetResult sample_set(const std::string& name, Dataset dataset, Aggregation aggregation) {
  SetResult r;
  r.name = name;
  r.dataset = dataset;
  r.aggregation = aggregation;
  r.summary = Summary{3, 1000, 1.25, 0.0625, 0.5, 0.75, 0.875};
  r.sequences = {{"alley_1", Summary{2, 600, 0.5, 0.0, 0.75, 1.0, 1.0}},
                 {"market \"5\"", Summary{1, 400, 2.375, 0.15625, 0.125, 0.375, 0.6875}}};
  return r;
}

// Runs python3 on a script with the JSON file as argv[1]; its exit status.
int run_python(const std::string& json, const std::string& script) {
  const std::string python = NEUFLOW_EVAL_PYTHON3;
  if (python.empty()) return -1;
  neuflow::test::TempDir dir;
  std::ofstream(dir.path() / "out.json") << json;
  std::ofstream(dir.path() / "check.py") << script;
  const std::string command =
      python + " " + (dir.path() / "check.py").string() + " " + (dir.path() / "out.json").string();
  return std::system(command.c_str());
}

TEST(EvalReport, TableHasOneRowPerSetAndSequencesOnRequest) {
  const std::vector<SetResult> results{sample_set("sintel-clean", Dataset::sintel, Aggregation::pooled_pixels)};
  const std::string table = format_table(results, false);
  EXPECT_EQ(table,
            "set             pairs       EPE     <1px     <3px     <5px\n"
            "sintel-clean        3     1.250   50.00%   75.00%   87.50%\n");
  const std::string detailed = format_table(results, true);
  EXPECT_NE(detailed.find("\n  alley_1           2     0.500   75.00%  100.00%  100.00%\n"), std::string::npos)
      << detailed;
  EXPECT_NE(detailed.find("\n  market \"5\"        1     2.375"), std::string::npos) << detailed;
}

TEST(EvalReport, KittiTableShowsFlAllAndMissingNumbersAsNotAvailable) {
  SetResult kitti = sample_set("kitti", Dataset::kitti, Aggregation::mean_of_images);
  kitti.summary.epe = std::numeric_limits<double>::infinity();
  kitti.summary.within_1px = std::numeric_limits<double>::quiet_NaN();
  const std::string table = format_table({kitti}, false);
  EXPECT_EQ(table,
            "set      pairs       EPE   Fl-all     <1px     <3px     <5px\n"
            "kitti        3       inf    6.25%      n/a   75.00%   87.50%\n");
}

TEST(EvalReport, JsonParsesWithTheDocumentedKeys) {
  if (std::string(NEUFLOW_EVAL_PYTHON3).empty()) GTEST_SKIP() << "no python3 to parse the JSON with";
  RunDescription run;
  run.dataset = Dataset::sintel;
  run.root = "/data/Sintel \"quoted\"\\dir";
  run.model = "/models/neuflow_sintel.pth";
  run.iterations = {1, 8};
  run.max_pairs = 0;
  std::vector<SetResult> results{sample_set("sintel-clean", Dataset::sintel, Aggregation::pooled_pixels),
                                 sample_set("sintel-final", Dataset::sintel, Aggregation::pooled_pixels)};
  results[1].summary.epe = std::numeric_limits<double>::quiet_NaN();
  const std::string json = format_json(run, results, true);
  EXPECT_EQ(run_python(json, R"(
import json, sys
d = json.load(open(sys.argv[1]))
assert d["dataset"] == "sintel", d
assert d["root"] == '/data/Sintel "quoted"\\dir', d["root"]
assert d["source"] == "model" and d["model"] == "/models/neuflow_sintel.pth"
assert d["iters_s16"] == 1 and d["iters_s8"] == 8 and d["channel_order"] == "rgb"
assert d["max_pairs"] is None
r = d["results"]
assert [x["set"] for x in r] == ["sintel-clean", "sintel-final"]
keys = {"set", "pairs", "valid_pixels", "epe", "fl_all", "within_1px", "within_3px", "within_5px",
        "epe_aggregation", "sequences"}
assert set(r[0]) == keys, set(r[0])
assert r[0]["epe"] == 1.25 and r[0]["pairs"] == 3 and r[0]["valid_pixels"] == 1000
assert r[0]["fl_all"] == 0.0625 and r[0]["within_5px"] == 0.875
assert r[0]["epe_aggregation"] == "pixels"
assert r[1]["epe"] is None
s = r[0]["sequences"]
assert [x["sequence"] for x in s] == ["alley_1", 'market "5"'], s
assert s[1]["epe"] == 2.375 and s[1]["pairs"] == 1
)"),
            0);

  RunDescription predictions;
  predictions.dataset = Dataset::kitti;
  predictions.root = "/data/KITTI";
  predictions.predictions = "/out/pred";
  predictions.max_pairs = 5;
  EXPECT_EQ(
      run_python(format_json(predictions, {sample_set("kitti", Dataset::kitti, Aggregation::mean_of_images)}, false),
                 R"(
import json, sys
d = json.load(open(sys.argv[1]))
assert d["source"] == "predictions" and d["predictions"] == "/out/pred", d
assert "model" not in d and "iters_s8" not in d
assert d["max_pairs"] == 5
r = d["results"][0]
assert r["epe_aggregation"] == "images" and "sequences" not in r, r
)"),
      0);
}

}  // namespace
}  // namespace neuflow::eval
