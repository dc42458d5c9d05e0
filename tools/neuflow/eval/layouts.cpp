#include "neuflow/eval/layouts.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "neuflow/eval/errors.hpp"

namespace neuflow::eval {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void missing(const std::string& message) { throw EvalError(EvalError::Kind::missing_input, message); }
[[noreturn]] void malformed(const std::string& message) { throw EvalError(EvalError::Kind::malformed_input, message); }

bool ends_with(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Entries of a folder, sorted by name: the benchmarks number their files with zero padding,
// so name order is frame order (as the reference's sorted(glob(...)) relies on too).
std::vector<std::string> list_names(const fs::path& dir, bool want_dirs, std::string_view suffix = {}) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    // A broken link is no folder; as a file it fails later, naming itself, when it is read.
    std::error_code entry_ec;
    const bool is_dir = it->is_directory(entry_ec);
    const std::string name = it->path().filename().string();
    if (want_dirs ? is_dir : (!is_dir && ends_with(name, suffix))) names.push_back(name);
  }
  if (ec) missing(dir.string() + ": cannot list the folder (" + ec.message() + ")");
  std::sort(names.begin(), names.end());
  return names;
}

void require_file(const fs::path& file, const fs::path& for_ground_truth) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    missing(file.string() + ": no such image (one of the pair for ground truth " + for_ground_truth.string() + ")");
  }
}

void require_root(const fs::path& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) missing(root.string() + ": no such dataset folder");
}

// The folder holding `subdirs`: root itself or root/training (the usual download unpacks
// into ROOT/training), whichever has them all; both having them is ambiguous.
fs::path find_base(const fs::path& root, const std::vector<std::string>& subdirs, std::string_view dataset,
                   bool allow_training) {
  require_root(root);
  std::vector<fs::path> candidates;
  if (allow_training) candidates.push_back(root / "training");
  candidates.push_back(root);
  std::vector<fs::path> found;
  for (const auto& c : candidates) {
    std::error_code ec;
    if (std::all_of(subdirs.begin(), subdirs.end(),
                    [&](const std::string& s) { return fs::is_directory(c / s, ec); })) {
      found.push_back(c);
    }
  }
  std::string wanted;
  for (const auto& s : subdirs) wanted += (wanted.empty() ? "" : ", ") + s + "/";
  if (found.size() > 1) {
    missing(root.string() + ": ambiguous " + std::string(dataset) + " layout: both " + found[0].string() + " and " +
            found[1].string() + " hold " + wanted + "; point ROOT at the one to evaluate");
  }
  if (found.empty()) {
    std::string where;
    for (const auto& c : candidates) where += (where.empty() ? "" : " or ") + c.string();
    missing(root.string() + ": not a " + std::string(dataset) + " layout: looked for the folders " + wanted + " in " +
            where);
  }
  return found.front();
}

// A set with no pairs yet, scored and padded the way its benchmark's reference evaluation does.
EvalSet new_set(std::string name, Dataset dataset, PadMode pad_mode, Aggregation aggregation, fs::path root) {
  EvalSet set;
  set.name = std::move(name);
  set.dataset = dataset;
  set.pad_mode = pad_mode;
  set.aggregation = aggregation;
  set.root = std::move(root);
  return set;
}

std::vector<EvalSet> sintel_sets(const fs::path& root, SintelPass which) {
  std::vector<std::string> passes;
  if (which != SintelPass::final) passes.emplace_back("clean");
  if (which != SintelPass::clean) passes.emplace_back("final");
  std::vector<std::string> subdirs{"flow"};
  subdirs.insert(subdirs.end(), passes.begin(), passes.end());
  const fs::path base = find_base(root, subdirs, "MPI-Sintel", true);

  std::vector<EvalSet> sets;
  for (const auto& pass : passes) {
    EvalSet set = new_set("sintel-" + pass, Dataset::sintel, PadMode::centred, Aggregation::pooled_pixels, base);
    for (const auto& scene : list_names(base / "flow", true)) {
      const fs::path image_dir = base / pass / scene;
      const auto flows = list_names(base / "flow" / scene, false, ".flo");
      if (flows.empty()) continue;
      std::error_code ec;
      if (!fs::is_directory(image_dir, ec)) {
        missing(image_dir.string() + ": no such folder (the " + pass + " images for " +
                (base / "flow" / scene).string() + ")");
      }
      const auto images = list_names(image_dir, false, ".png");
      for (const auto& flo : flows) {
        const std::string stem = flo.substr(0, flo.size() - 4);
        const fs::path gt = base / "flow" / scene / flo;
        const auto first = std::lower_bound(images.begin(), images.end(), stem + ".png");
        if (first == images.end() || *first != stem + ".png") {
          missing((image_dir / (stem + ".png")).string() + ": no such image (the first of the pair of ground truth " +
                  gt.string() + ")");
        }
        if (std::next(first) == images.end()) {
          missing(image_dir.string() + ": no frame after " + stem + ".png (the second image for " + gt.string() + ")");
        }
        set.pairs.push_back(
            {image_dir / *first, image_dir / *std::next(first), gt, scene, pass + "/" + scene + "/" + stem});
      }
    }
    if (set.pairs.empty())
      missing((base / "flow").string() + ": no <scene>/*.flo ground truth in the MPI-Sintel layout");
    sets.push_back(std::move(set));
  }
  return sets;
}

EvalSet kitti_set(const fs::path& root) {
  const fs::path base = find_base(root, {"image_2", "flow_occ"}, "KITTI-2015", true);
  EvalSet set = new_set("kitti", Dataset::kitti, PadMode::bottom, Aggregation::mean_of_images, base);
  for (const auto& name : list_names(base / "flow_occ", false, "_10.png")) {
    const std::string id = name.substr(0, name.size() - 7);
    const fs::path gt = base / "flow_occ" / name;
    Pair pair{base / "image_2" / (id + "_10.png"), base / "image_2" / (id + "_11.png"), gt, id,
              "image_2/" + id + "_10"};
    require_file(pair.image0, gt);
    require_file(pair.image1, gt);
    set.pairs.push_back(std::move(pair));
  }
  if (set.pairs.empty()) missing((base / "flow_occ").string() + ": no *_10.png ground truth in the KITTI-2015 layout");
  return set;
}

// flowNN.flo names frameNN.png → frame(NN+1).png, the number's width kept (flow10.flo:
// frame10.png, frame11.png). Other names are not Middlebury ground truth.
std::optional<std::pair<std::string, std::string>> middlebury_frames(const std::string& flo) {
  if (flo.size() <= 8 || flo.compare(0, 4, "flow") != 0 || !ends_with(flo, ".flo")) return std::nullopt;
  const std::string digits = flo.substr(4, flo.size() - 8);
  if (digits.size() > 6 ||
      !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return std::nullopt;
  }
  std::string next = std::to_string(std::stoi(digits) + 1);
  if (next.size() < digits.size()) next.insert(0, digits.size() - next.size(), '0');
  return std::make_pair("frame" + digits, "frame" + next);
}

EvalSet middlebury_set(const fs::path& root) {
  const fs::path base = find_base(root, {"other-data", "other-gt-flow"}, "Middlebury", false);
  EvalSet set = new_set("middlebury", Dataset::middlebury, PadMode::centred, Aggregation::pooled_pixels, base);
  for (const auto& seq : list_names(base / "other-gt-flow", true)) {
    for (const auto& flo : list_names(base / "other-gt-flow" / seq, false, ".flo")) {
      const auto frames = middlebury_frames(flo);
      if (!frames) continue;
      const fs::path gt = base / "other-gt-flow" / seq / flo;
      const fs::path dir = base / "other-data" / seq;
      Pair pair{dir / (frames->first + ".png"), dir / (frames->second + ".png"), gt, seq,
                "other-data/" + seq + "/" + frames->first};
      require_file(pair.image0, gt);
      require_file(pair.image1, gt);
      set.pairs.push_back(std::move(pair));
    }
  }
  if (set.pairs.empty()) {
    missing((base / "other-gt-flow").string() + ": no <sequence>/flowNN.flo ground truth in the Middlebury layout");
  }
  return set;
}

// FlyingChairs_train_val.txt: one label per pair in name order, 1 = training, 2 = validation.
std::vector<int> read_chairs_split(const fs::path& file, std::size_t pairs) {
  std::ifstream in(file);
  if (!in) missing(file.string() + ": cannot read the split file");
  std::vector<int> labels;
  std::string token;
  while (in >> token) {
    if (token != "1" && token != "2") {
      malformed(file.string() + ": entry " + std::to_string(labels.size() + 1) + " is '" + token +
                "', expected 1 (training) or 2 (validation)");
    }
    labels.push_back(token == "1" ? 1 : 2);
  }
  if (labels.size() != pairs) {
    malformed(file.string() + ": " + std::to_string(labels.size()) + " labels for " + std::to_string(pairs) +
              " *_flow.flo files; expected one label per pair");
  }
  return labels;
}

EvalSet chairs_set(const fs::path& root) {
  require_root(root);
  std::error_code ec;
  const bool has_data = fs::is_directory(root / "data", ec);
  const fs::path data = has_data ? root / "data" : root;
  const auto flows = list_names(data, false, "_flow.flo");
  if (flows.empty()) {
    missing(root.string() + ": not a FlyingChairs layout: no *_flow.flo files in " + data.string() +
            (has_data ? "" : " (nor a data/ folder)"));
  }
  EvalSet set = new_set("chairs", Dataset::chairs, PadMode::centred, Aggregation::pooled_pixels, data);

  std::vector<int> labels;
  // The release keeps the split file beside data/.
  for (const fs::path& dir : {data.parent_path(), data}) {
    if (fs::is_regular_file(dir / "FlyingChairs_train_val.txt", ec)) {
      labels = read_chairs_split(dir / "FlyingChairs_train_val.txt", flows.size());
      set.name = "chairs-val";
      break;
    }
  }
  for (std::size_t i = 0; i < flows.size(); ++i) {
    if (!labels.empty() && labels[i] != 2) continue;
    const std::string id = flows[i].substr(0, flows[i].size() - 9);
    const fs::path gt = data / flows[i];
    Pair pair{data / (id + "_img1.ppm"), data / (id + "_img2.ppm"), gt, id, id + "_img1"};
    require_file(pair.image0, gt);
    require_file(pair.image1, gt);
    set.pairs.push_back(std::move(pair));
  }
  if (set.pairs.empty()) missing(data.string() + ": the split file marks no pair for validation (label 2)");
  return set;
}

}  // namespace

std::optional<Dataset> parse_dataset(std::string_view name) {
  for (Dataset d : {Dataset::sintel, Dataset::kitti, Dataset::middlebury, Dataset::chairs}) {
    if (name == to_string(d)) return d;
  }
  return std::nullopt;
}

std::string_view to_string(Dataset dataset) {
  switch (dataset) {
    case Dataset::sintel: return "sintel";
    case Dataset::kitti: return "kitti";
    case Dataset::middlebury: return "middlebury";
    case Dataset::chairs: return "chairs";
  }
  return "unknown";
}

std::vector<EvalSet> discover_sets(Dataset dataset, const fs::path& given_root, const LayoutOptions& options) {
  // Absolute and without a trailing separator, so parent_path() means the enclosing folder.
  fs::path root = fs::absolute(given_root).lexically_normal();
  if (!root.has_filename() && root.has_parent_path() && root != root.root_path()) root = root.parent_path();
  switch (dataset) {
    case Dataset::sintel: return sintel_sets(root, options.sintel_pass);
    case Dataset::kitti: return {kitti_set(root)};
    case Dataset::middlebury: return {middlebury_set(root)};
    case Dataset::chairs: return {chairs_set(root)};
  }
  return {};
}

}  // namespace neuflow::eval
