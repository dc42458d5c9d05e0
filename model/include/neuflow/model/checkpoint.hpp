#pragma once
// Reading PyTorch `.pth` checkpoints (state dicts) without Python and without executing any
// code from the file.
//
// Supported: the zip container that torch.save has written since PyTorch 1.6 (any top-level
// folder name, `<folder>/data.pkl` + `<folder>/data/<key>`), pickle protocols 2..5, and only
// the pickle opcodes and globals a state dict needs. Globals other than
// collections.OrderedDict, torch._utils._rebuild_tensor_v2, torch._utils._rebuild_parameter
// and torch.{Float,Half,BFloat16,Double,Long,Int}Storage are rejected (CheckpointError of
// kind kUnsafe naming the global) before anything from the file is acted upon.
// The legacy (pre-1.6, non-zip) format is recognised and rejected with a conversion hint.
//
// Accepted layouts of the pickled object: {'model': state_dict}, {'state_dict': state_dict}
// (other entries beside these are ignored, but must still consist of allowed globals), or a
// bare state dict {name: tensor}. A `module.` prefix present on every key (DataParallel) is
// stripped.
#include <cstdint>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace neuflow::model {

// Every failure of load_checkpoint. what() names the file and the problem.
class CheckpointError : public std::runtime_error {
 public:
  enum class Kind {
    kIo,           // missing, unreadable or a directory
    kFormat,       // malformed: not a checkpoint, truncated, inconsistent, too large
    kUnsupported,  // well-formed but not supported (legacy format, dtype, object type)
    kUnsafe,       // the pickle references a global outside the allow-list
  };
  CheckpointError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

// One tensor of a state dict, converted to float32, contiguous row-major (C order).
struct CheckpointTensor {
  std::vector<int64_t> shape;  // empty for a scalar (e.g. BatchNorm num_batches_tracked)
  std::vector<float> data;     // numel() values; int64/int32 values are converted too
                               // (exact up to 2^24)
  std::string dtype;           // dtype in the file: "float32", "float16", "bfloat16",
                               // "float64", "int64" or "int32"

  int64_t numel() const {
    int64_t n = 1;
    for (const int64_t d : shape) n *= d;
    return n;
  }
};

struct Checkpoint {
  std::string path;                                 // as given to load_checkpoint
  std::string container;                            // e.g. "PyTorch zip (folder 'archive/'), pickle protocol 2"
  std::string wrapper;                              // where the state dict was: "model", "state_dict" or "bare"
  bool stripped_module_prefix = false;              // every key had "module." and it was removed
  std::vector<std::string> keys;                    // state-dict keys in file order (prefix stripped)
  std::map<std::string, CheckpointTensor> tensors;  // by key

  // The tensor named `key`, or nullptr.
  const CheckpointTensor* find(const std::string& key) const;
  // The tensor named `key`; throws CheckpointError (kFormat) naming the file and the key.
  const CheckpointTensor& at(const std::string& key) const;
};

// "[576, 512, 1, 1]", as PyTorch prints a shape; "[]" for a scalar.
std::string shape_text(const std::vector<int64_t>& shape);

// Reads a checkpoint completely (all tensors, converted to float32). Throws CheckpointError.
Checkpoint load_checkpoint(const std::filesystem::path& path);

// The same checks of the container and the pickle, and of each storage's size, but no tensor
// data is read: every tensor has its shape and dtype and empty data. For checking that a
// file is a NeuFlow-V2 checkpoint (find_architecture_mismatch) without loading 36 MB.
Checkpoint read_checkpoint_header(const std::filesystem::path& path);

}  // namespace neuflow::model
