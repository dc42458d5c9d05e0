// neuflow_fuzz_seeds OUTDIR: writes the seed corpus of every harness, OUTDIR/<harness>/...,
// with the project's own writers (flow formats) and the checkpoint builder of the model tests,
// plus the shipped configs (config/*.toml) and tests/fuzz/regressions/<harness>/*. Every
// generated seed is read back and must be accepted, so a format change that made them useless
// fails here (ctest fuzz_seeds) rather than silently weakening the fuzzing.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "checkpoint_builder.hpp"
#include "checkpoint_support.hpp"
#include "config.hpp"
#include "neuflow/flow/flo_format.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/flow/kitti_png_format.hpp"
#include "neuflow/flow/npy_format.hpp"
#if NEUFLOW_FUZZ_SINK_SEEDS
#include "flow_ring_writer.hpp"
#endif
#include "neuflow/flow_ring.hpp"
#include "neuflow/model/checkpoint.hpp"

namespace fs = std::filesystem;
using neuflow::flow::FlowField;
using neuflow::test::FakeCheckpoint;
using neuflow::test::FakeTensor;
using neuflow::test::Wrapper;

namespace {

std::map<std::string, int> written;  // seeds per harness

fs::path seed_path(const fs::path& out, const std::string& harness, const std::string& name) {
  ++written[harness];
  return out / harness / name;
}

// ---- flow fields ------------------------------------------------------------------------

FlowField ramp(int width, int height, float scale) {
  FlowField f(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      f.u(x, y) = scale * (0.25f * static_cast<float>(x) - 1.5f + 0.01f * static_cast<float>(y));
      f.v(x, y) = scale * (-0.5f * static_cast<float>(y) + 0.75f - 0.02f * static_cast<float>(x));
    }
  }
  return f;
}

FlowField masked(FlowField f) {
  f.valid.assign(f.pixel_count(), 1);
  for (std::size_t i = 0; i < f.valid.size(); i += 3) f.valid[i] = 0;
  return f;
}

std::vector<FlowField> sample_fields() {
  return {ramp(1, 1, 1.f), ramp(4, 3, 1.f), masked(ramp(5, 2, 10.f)), ramp(3, 7, 100.f)};
}

// An .npy file written by hand, for the header variants write_npy never produces.
std::string npy(int major, std::string header, std::size_t floats) {
  const std::size_t prefix = major == 1 ? 10 : 12;
  const std::size_t unpadded = prefix + header.size() + 1;
  header.append((64 - unpadded % 64) % 64, ' ');
  header += '\n';
  std::string out = std::string("\x93NUMPY", 6) + static_cast<char>(major) + '\0';
  for (std::size_t i = 0; i < prefix - 8; ++i) out += static_cast<char>((header.size() >> (8 * i)) & 0xffu);
  out += header;
  for (std::size_t i = 0; i < floats; ++i) {
    out += neuflow::test::le_floats({0.5f * static_cast<float>(i) - 1.f});
  }
  return out;
}

void write_flow_seeds(const fs::path& out) {
  int i = 0;
  for (const auto& field : sample_fields()) {
    const std::string stem =
        "field-" + std::to_string(i++) + "-" + std::to_string(field.width) + "x" + std::to_string(field.height);
    neuflow::flow::write_flo(field, seed_path(out, "flo", stem + ".flo"));
    neuflow::flow::write_npy(field, seed_path(out, "npy", stem + ".npy"));
    neuflow::flow::write_kitti_png(field, seed_path(out, "kitti_png", stem + ".png"));
  }
  // Header variants: versions 2.0 and 3.0, Python 2 longs, other shapes for read_npy_array,
  // and two that are refused after parsing (float64, Fortran order).
  const std::vector<std::pair<std::string, std::string>> variants = {
      {"v2-2x2x2.npy", npy(2, "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2, 2), }", 8)},
      {"v3-1x3x2.npy", npy(3, "{\"descr\": \"<f4\", \"fortran_order\": False, \"shape\": (1, 3, 2)}", 6)},
      {"py2-long.npy", npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (2L, 1L, 2L), }", 4)},
      {"vector-5.npy", npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (5,), }", 5)},
      {"scalar.npy", npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (), }", 1)},
      {"empty-0x4.npy", npy(1, "{'descr': '<f4', 'fortran_order': False, 'shape': (0, 4), }", 0)},
      {"float64.npy", npy(1, "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1, 2), }", 4)},
      {"fortran.npy", npy(1, "{'descr': '<f4', 'fortran_order': True, 'shape': (2, 1, 2), }", 4)},
  };
  for (const auto& [name, bytes] : variants) neuflow::test::write_file(seed_path(out, "npy", name), bytes);
}

// ---- checkpoints ------------------------------------------------------------------------

FakeTensor tensor(std::string name, std::string type, std::string key, int64_t storage_numel, int64_t offset,
                  std::vector<int64_t> size, std::vector<int64_t> stride = {}, bool parameter = false) {
  FakeTensor t;
  t.name = std::move(name);
  t.storage_type = std::move(type);
  t.storage_key = std::move(key);
  t.storage_numel = storage_numel;
  t.offset = offset;
  t.size = std::move(size);
  t.stride = std::move(stride);
  t.as_parameter = parameter;
  return t;
}

// Small state dicts over the storages the pickle harness provides (data/0..3, 256 bytes
// each): every wrapper, every dtype, views with offsets and strides, parameters, scalars.
std::vector<std::pair<std::string, FakeCheckpoint>> sample_checkpoints() {
  std::vector<std::pair<std::string, FakeCheckpoint>> out;
  const auto add = [&](std::string name, Wrapper wrapper, std::vector<FakeTensor> tensors) {
    FakeCheckpoint c;
    c.folder = neuflow::fuzz::kPickleFolder;
    c.wrapper = wrapper;
    c.tensors = std::move(tensors);
    for (int i = 0; i < neuflow::fuzz::kPickleStorages; ++i) {
      c.storages.emplace_back(std::to_string(i), neuflow::fuzz::pickle_storage_bytes(i));
    }
    out.emplace_back(std::move(name), std::move(c));
  };
  add("model-conv-bn", Wrapper::kModel,
      {tensor("conv.weight", "FloatStorage", "0", 64, 0, {2, 3, 2, 2}, {}, true),
       tensor("conv.bias", "FloatStorage", "0", 64, 24, {2}),
       tensor("bn.running_mean", "FloatStorage", "0", 64, 26, {2}),
       tensor("bn.num_batches_tracked", "LongStorage", "1", 32, 0, {})});
  add("state-dict-dtypes", Wrapper::kStateDict,
      {tensor("half", "HalfStorage", "2", 128, 0, {4, 4}), tensor("bf16", "BFloat16Storage", "3", 128, 5, {8}),
       tensor("transposed", "FloatStorage", "0", 64, 0, {3, 2}, {1, 3}),
       tensor("empty", "FloatStorage", "0", 64, 0, {0, 5})});
  add("bare-module-prefix", Wrapper::kBare,
      {tensor("module.a", "DoubleStorage", "1", 32, 0, {2, 2}), tensor("module.b", "IntStorage", "2", 64, 3, {5}),
       tensor("module.c", "FloatStorage", "0", 64, 1, {2, 2, 2}, {16, 4, 1})});
  add("ordered-dict-metadata", Wrapper::kOrderedDictWithMetadata,
      {tensor("backbone.w", "FloatStorage", "0", 64, 0, {4, 4}),
       tensor("backbone.b", "FloatStorage", "0", 64, 60, {4})});
  add("model-with-extras", Wrapper::kModelWithExtras,
      {tensor("w", "FloatStorage", "3", 64, 0, {1, 1, 8, 8}),
       tensor("broadcast", "FloatStorage", "3", 64, 0, {4, 4}, {0, 1})});
  return out;
}

// A protocol-4 pickle as newer torch writes it: FRAME, SHORT_BINUNICODE, MEMOIZE, STACK_GLOBAL.
std::string protocol4_pickle() {
  neuflow::test::PickleWriter w;
  w.proto(4).frame(0).empty_dict().memoize().short_str("model").memoize().empty_dict().memoize();
  w.short_str("layer.weight").memoize();
  w.short_str("torch._utils").short_str("_rebuild_tensor_v2").op(0x93).memoize();
  w.mark().mark().short_str("storage").short_str("torch").short_str("FloatStorage").op(0x93).memoize();
  w.short_str("0").short_str("cpu").integer(64).tuple().binpersid();
  w.integer(2).integer(3).integer(4).tuple2().integer(4).integer(1).tuple2().boolean(false);
  w.short_str("collections").short_str("OrderedDict").op(0x93).empty_tuple().reduce();
  w.tuple().reduce().memoize().setitem().setitem().stop();
  return w.bytes();
}

void write_checkpoint_seeds(const fs::path& out) {
  for (auto [name, checkpoint] : sample_checkpoints()) {
    neuflow::test::write_file(seed_path(out, "checkpoint_pickle", name + ".pkl"), checkpoint.pickle());
    checkpoint.write(seed_path(out, "checkpoint", name + ".pth"));
  }
  neuflow::test::write_file(seed_path(out, "checkpoint_pickle", "protocol4.pkl"), protocol4_pickle());

  // Whole-file variants: a folder named after the file, deflated entries, big-endian storages.
  const FakeCheckpoint base = sample_checkpoints().front().second;
  FakeCheckpoint renamed = base;
  renamed.folder = "neuflow_mixed";
  renamed.write(seed_path(out, "checkpoint", "folder-neuflow_mixed.pth"));
  auto entries = base.entries();
  for (auto& entry : entries) entry.compress = true;
  neuflow::test::write_zip(seed_path(out, "checkpoint", "deflated.pth"), entries);
  entries = base.entries();
  entries.push_back({base.folder + "/byteorder", "big"});
  neuflow::test::write_zip(seed_path(out, "checkpoint", "big-endian.pth"), entries);
}

// ---- configs ----------------------------------------------------------------------------

void copy_seeds(const fs::path& from, const fs::path& out, const std::string& harness) {
  if (!fs::is_directory(from)) return;
  for (const auto& entry : fs::directory_iterator(from)) {
    if (!entry.is_regular_file()) continue;
    fs::copy_file(entry.path(), seed_path(out, harness, entry.path().filename().string()),
                  fs::copy_options::overwrite_existing);
  }
}

// ---- the sinks' and the daemon's small formats -----------------------------------------

void write_text(const fs::path& path, const std::string& text) { neuflow::test::write_file(path, text); }

#if NEUFLOW_FUZZ_SINK_SEEDS
// The segment the shm sink's writer makes after publishing `flows` flows of 4×2 into `slots`
// slots (docs/shm-ring.md), read from /dev/shm before the writer unlinks it.
std::string written_ring(std::uint32_t slots, int flows) {
  const std::string name = "/neuflow-fuzz-seed-" + std::to_string(::getpid());
  neuflow::gst::FlowRingWriter writer(name, slots, 7);
  std::vector<float> uv(4 * 2 * 2);
  for (int n = 1; n <= flows; ++n) {
    for (std::size_t i = 0; i < uv.size(); ++i) uv[i] = static_cast<float>(n) + 0.25f * static_cast<float>(i);
    neuflow::gst::FlowRecord record;
    record.from_frame = static_cast<std::uint64_t>(n - 1);
    record.to_frame = static_cast<std::uint64_t>(n);
    record.frame_width = record.model_width = 64;
    record.frame_height = record.model_height = 32;
    record.iters_s16 = 1;
    record.iters_s8 = 8;
    writer.publish(4, 2, record, uv);
  }
  return neuflow::test::read_file("/dev/shm" + name);
}
#endif

void write_sink_seeds(const fs::path& out) {
#if NEUFLOW_FUZZ_SINK_SEEDS
  write_text(seed_path(out, "ring_reader", "wrapped.ring"), written_ring(3, 4));
  write_text(seed_path(out, "ring_reader", "one.ring"), written_ring(2, 1));
#endif
  write_text(seed_path(out, "flow_index", "index.csv"),
             "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source\n"
             "0,0,1,0,33333333,flow_00000.flo,,\n"
             "1,1,2,33333333,66666666,flow_00001.flo,,\n");
  write_text(seed_path(out, "flow_index", "quoted.csv"),
             "index,from_frame,to_frame,from_pts_ns,to_pts_ns,file,from_source,to_source\r\n"
             "0,0,1,,,\"a,b.flo\",\"x \"\"1\"\".png\",\"line\nbreak.png\"\r\n");
  write_text(seed_path(out, "retention", "padded.txt"),
             "flow_%05d.flo\nflow_00001.flo\nflow_00042.flo\nflow_7.flo\nflow_-0005.flo\nflow_123456789012.flo\n");
  write_text(seed_path(out, "retention", "plain.txt"), "f%d.npy\nf0.npy\nf12.npy\nf012.npy\nf+1.npy\nindex.csv\n");
  write_text(seed_path(out, "retention", "percent.txt"), "%%_%3d.png\n%_  7.png\n%_ 17.png\n%_017.png\n");
  const std::pair<const char*, const char*> values[] = {
      {"name.txt", "front-camera_1"},   {"host.txt", "127.0.0.1:8554"}, {"ipv6.txt", "[::1]:5000"},
      {"shm.txt", "/neuflow-front"},    {"mode.txt", "0640"},           {"mount.txt", "/cameras/front"},
      {"pattern.txt", "flow_%05d.flo"}, {"rate.txt", "30000/1001"},     {"percent.txt", "100%%_%d.mp4"},
  };
  for (const auto& [name, text] : values) write_text(seed_path(out, "config_values", name), text);
}

// ---- checks -----------------------------------------------------------------------------

// Every generated seed must be accepted: returns the number refused (and says which).
int check_seeds(const fs::path& out) {
  int refused = 0;
  const auto check = [&](const std::string& harness, const std::function<void(const fs::path&)>& accept,
                         const std::function<bool(const fs::path&)>& skip = {}) {
    for (const auto& entry : fs::directory_iterator(out / harness)) {
      if (skip && skip(entry.path())) continue;
      try {
        accept(entry.path());
      } catch (const std::exception& e) {
        std::fprintf(stderr, "seed %s is refused: %s\n", entry.path().c_str(), e.what());
        ++refused;
      }
    }
  };
  const auto refused_by_design = [](const fs::path& p) {
    const auto name = p.filename().string();
    return name == "float64.npy" || name == "fortran.npy";
  };
  check("flo", [](const fs::path& p) { neuflow::flow::read_flo(p); });
  check(
      "npy", [](const fs::path& p) { neuflow::flow::read_npy_array(p); }, refused_by_design);
  check("kitti_png", [](const fs::path& p) { neuflow::flow::read_kitti_png(p); });
  check("checkpoint", [](const fs::path& p) { neuflow::model::load_checkpoint(p); });
  check("checkpoint_pickle", [&](const fs::path& p) {
    const fs::path zip = out / "checkpoint_pickle.check.pth";
    neuflow::test::write_file(zip, neuflow::fuzz::checkpoint_around_pickle(neuflow::test::read_file(p)));
    neuflow::model::load_checkpoint(zip);
  });
  fs::remove(out / "checkpoint_pickle.check.pth");
  // A ring seed opens, and its newest flow reads back whole with a matching checksum.
  check("ring_reader", [](const fs::path& p) {
    const std::string name = "/neuflow-fuzz-seed-" + std::to_string(::getpid());
    const std::string bytes = neuflow::test::read_file(p);
    const int fd = ::shm_open(name.c_str(), O_CREAT | O_RDWR | O_TRUNC, 0600);
    if (fd < 0 || ::ftruncate(fd, static_cast<off_t>(bytes.size())) != 0 ||
        ::pwrite(fd, bytes.data(), bytes.size(), 0) != static_cast<ssize_t>(bytes.size())) {
      throw std::runtime_error("cannot write a shared-memory segment");
    }
    ::close(fd);
    try {
      const neuflow::ring::FlowRingReader reader(name);
      std::vector<float> uv(reader.values_per_flow());
      neuflow::ring::FlowInfo info;
      const auto status = reader.latest(uv, info);
      if (reader.published() > 0 && (status != neuflow::ring::ReadStatus::ok || !neuflow::ring::verify(uv, info))) {
        throw std::runtime_error("its newest flow does not read back");
      }
    } catch (...) {
      ::shm_unlink(name.c_str());
      throw;
    }
    ::shm_unlink(name.c_str());
  });
  // The shipped configs must load on the file alone; the regression inputs are refused.
  check(
      "config",
      [](const fs::path& p) {
        neuflow::daemon::parse_config(neuflow::test::read_file(p), "/fuzz/" + p.filename().string(),
                                      neuflow::daemon::ConfigChecks::file_only);
      },
      [](const fs::path& p) { return fs::exists(fs::path(NEUFLOW_FUZZ_REGRESSIONS_DIR) / "config" / p.filename()); });
  return refused;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTDIR\nWrites the seed corpus of each fuzz harness into OUTDIR/<harness>/.\n",
                 argv[0]);
    return 2;
  }
  const fs::path out = argv[1];
  try {
    const std::vector<std::string> harnesses = {
        "flo",    "npy",           "kitti_png",   "checkpoint", "checkpoint_pickle",
        "config", "config_values", "ring_reader", "flow_index", "retention"};
    for (const auto& harness : harnesses) {
      fs::remove_all(out / harness);
      fs::create_directories(out / harness);
    }
    write_flow_seeds(out);
    write_checkpoint_seeds(out);
    write_sink_seeds(out);
    for (const auto& entry : fs::directory_iterator(NEUFLOW_CONFIG_DIR)) {
      if (entry.path().extension() == ".toml") {
        fs::copy_file(entry.path(), seed_path(out, "config", entry.path().filename().string()));
      }
    }
    for (const auto& harness : harnesses) copy_seeds(fs::path(NEUFLOW_FUZZ_REGRESSIONS_DIR) / harness, out, harness);

    if (const int refused = check_seeds(out); refused > 0) {
      std::fprintf(stderr, "%d seed(s) refused by the code they are meant to exercise\n", refused);
      return 1;
    }
    for (const auto& [harness, count] : written) std::printf("%-18s %3d seeds\n", harness.c_str(), count);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "neuflow_fuzz_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
