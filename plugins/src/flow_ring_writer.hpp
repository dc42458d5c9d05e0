#pragma once
// The writing side of the flow ring (layout: neuflow/flow_ring.hpp, docs/shm-ring.md), for
// the `neuflowshmsink` element: owns the shared-memory segment under one name, publishes
// flows into it with the seqlock protocol without ever waiting for readers, and replaces the
// segment (with the next generation) when the grid size changes. No GStreamer in here.
#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace neuflow::gst {

// The segment's default mode: readers run as the writer's user or in its group (neuflowd's
// units make that the fixed group `neuflow`, which reader accounts join); others cannot read.
inline constexpr mode_t kFlowRingMode = 0640;

// Why `mode` cannot be a flow ring's mode, or nullopt: read and write bits only (no execute,
// setuid, setgid or sticky bits), and the owner must be able to read and write.
std::optional<std::string> check_flow_ring_mode(mode_t mode);

// Why `name` cannot name a POSIX shared-memory segment ("/name": a leading slash, no other,
// at most 255 characters), or nullopt.
std::optional<std::string> check_flow_ring_name(std::string_view name);

class FlowRingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Everything publish() stores besides the grid size and the vectors.
struct FlowRecord {
  std::uint64_t from_frame = 0, to_frame = 0;
  std::uint64_t from_pts_ns = 0, to_pts_ns = 0;  // neuflow::ring::kNoTimestamp when unknown
  std::uint64_t inference_ns = 0;
  std::uint32_t frame_width = 0, frame_height = 0;
  std::uint32_t model_width = 0, model_height = 0;
  std::uint32_t iters_s16 = 0, iters_s8 = 0;
};

class FlowRingWriter {
 public:
  // Takes the name over and creates a placeholder segment (no slots yet, state
  // initializing) so that name clashes and permission problems show up at once rather than
  // at the first flow. A segment left under the name by a writer that died is replaced; one
  // whose writer still runs (it holds an flock on it) is not: that throws. The placeholder's
  // generation is `first_generation`, or one more than that of a replaced stale segment if
  // larger; each later segment gets the next. Throws FlowRingError naming the segment and
  // the reason.
  // Every segment gets `mode` exactly (whatever the umask), see check_flow_ring_mode.
  FlowRingWriter(std::string name, std::uint32_t slots, std::uint64_t first_generation, mode_t mode = kFlowRingMode);
  // Marks the segment closed and unlinks the name (if it still names this segment); readers
  // that have it mapped keep reading the flows it holds.
  ~FlowRingWriter();
  FlowRingWriter(const FlowRingWriter &) = delete;
  FlowRingWriter &operator=(const FlowRingWriter &) = delete;

  // Publishes one flow of width × height cells (`uv`: width * height * 2 floats); the first
  // flow, and any flow of another size than the last, first replaces the segment with one
  // sized for it. Throws FlowRingError (segment cannot be created or sized).
  void publish(std::uint32_t width, std::uint32_t height, const FlowRecord &record, std::span<const float> uv);

  const std::string &name() const { return name_; }
  std::uint64_t generation() const { return generation_; }
  // Flows published in the current segment.
  std::uint64_t published() const { return published_; }

 private:
  struct Segment {
    int fd = -1;
    std::byte *base = nullptr;
    std::size_t size = 0;
    dev_t dev = 0;
    ino_t ino = 0;
  };

  Segment create_segment(std::uint64_t size);
  void replace(std::uint32_t width, std::uint32_t height);
  void initialize_header(std::uint32_t width, std::uint32_t height, std::uint64_t stride, std::uint64_t data_bytes,
                         std::uint32_t state);
  void unlink_if_ours(const Segment &segment) const;
  static void release(Segment &segment);  // unmap, close (and so unlock)
  void retire(Segment &segment);          // mark closed, unlink if still ours, release
  [[noreturn]] void fail(const std::string &what, int err) const;

  std::string name_;
  std::uint32_t slots_;
  mode_t mode_;
  std::uint64_t generation_ = 0;
  std::uint64_t published_ = 0;
  std::uint32_t width_ = 0, height_ = 0;  // 0 × 0: the placeholder
  std::uint64_t stride_ = 0, data_bytes_ = 0;
  Segment segment_;
};

}  // namespace neuflow::gst
