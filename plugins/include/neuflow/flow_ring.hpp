// The neuflow flow ring: a POSIX shared-memory segment holding the latest N optical flows
// with their timestamps, written by the `neuflowshmsink` GStreamer element, and a
// header-only reader for it. C++20, the standard library and POSIX only: copy this one file
// into a consumer's tree. The layout, the seqlock protocol and generation handling are
// documented in docs/shm-ring.md; this header is their reference implementation.
//
//   neuflow::ring::FlowRingReader ring("/neuflow-front");
//   std::vector<float> uv(ring.values_per_flow());
//   neuflow::ring::FlowInfo info;
//   if (ring.latest(uv, info) == neuflow::ring::ReadStatus::ok && neuflow::ring::verify(uv, info)) { ... }
#ifndef NEUFLOW_FLOW_RING_HPP
#define NEUFLOW_FLOW_RING_HPP

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>

namespace neuflow::ring {

// Fields are stored in the host's byte order, which the layout fixes as little-endian; a
// big-endian consumer would need byte swaps, which this reader does not do.
static_assert(std::endian::native == std::endian::little, "the flow ring layout is little-endian");
static_assert(std::atomic_ref<std::uint64_t>::is_always_lock_free &&
                  std::atomic_ref<std::uint32_t>::is_always_lock_free,
              "the seqlock needs lock-free 32- and 64-bit atomics: a lock inside the library would not be shared "
              "between processes");

inline constexpr std::array<char, 8> kMagic = {'N', 'F', 'L', 'O', 'W', 'R', 'N', 'G'};
inline constexpr std::uint32_t kLayoutVersion = 1;
// The only value layout: float32 (u, v) interleaved per grid cell, rows top to bottom.
inline constexpr std::uint32_t kValueLayoutF32UV = 1;
// A timestamp the writer did not know (GStreamer's GST_CLOCK_TIME_NONE).
inline constexpr std::uint64_t kNoTimestamp = std::numeric_limits<std::uint64_t>::max();

// The rules for a ring's name and mode, the same for the element, neuflowd's config check and
// readers. A POSIX shared-memory name: '/' then 1 to NAME_MAX (255) characters, no other '/'.
inline constexpr std::size_t kMaxSegmentNameLength = 255;

// Why `name` cannot name a flow ring, or an empty string.
inline std::string segment_name_problem(std::string_view name) {
  if (name.empty()) return "it is empty; expected \"/name\", e.g. \"/neuflow-front\"";
  if (name.front() != '/') return "it must start with '/', e.g. \"/neuflow-front\"";
  if (name.size() == 1) return "it needs a name after the '/', e.g. \"/neuflow-front\"";
  if (name.find('/', 1) != std::string_view::npos) return "it must not contain a '/' after the first character";
  if (name.size() - 1 > kMaxSegmentNameLength) {
    return "it is longer than " + std::to_string(kMaxSegmentNameLength) + " characters after the '/'";
  }
  if (name == "/." || name == "/..") return "\".\" and \"..\" are not segment names";
  for (const char c : name) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "it contains a control character";
  }
  return {};
}

// Why `mode` cannot be a ring's permissions, or an empty string: read and write bits only (no
// execute, setuid, setgid or sticky bits), and the owner must be able to read and write.
inline std::string segment_mode_problem(unsigned mode) {
  if ((mode & ~0666u) != 0) {
    return "only read and write permission bits are allowed (at most 0666), no execute, setuid, setgid or sticky bits";
  }
  if ((mode & 0600u) != 0600u) return "the owner must keep read and write permission (at least 0600)";
  return {};
}

enum class SegmentState : std::uint32_t {
  initializing = 0,  // being created, or waiting for the first flow: retry later
  live = 1,          // the writer publishes here
  closed = 2,        // the writer stopped or replaced this segment: re-open the name
};

// At offset 0 of the segment. Every field but `state` and `flows_published` is written once,
// before `state` becomes live, and never changes afterwards.
struct RingHeader {
  char magic[8];                   // "NFLOWRNG"
  std::uint32_t version;           // kLayoutVersion
  std::uint32_t header_size;       // offset of slot 0
  std::uint32_t slot_count;        // N
  std::uint32_t slot_header_size;  // offset of the flow data inside a slot
  std::uint64_t slot_stride;       // bytes from one slot to the next
  std::uint32_t grid_width;        // every flow in this segment has this grid size
  std::uint32_t grid_height;
  std::uint32_t value_layout;     // kValueLayoutF32UV
  std::uint32_t state;            // SegmentState, atomic
  std::uint64_t generation;       // differs between successive segments under one name
  std::uint64_t flows_published;  // atomic: sequence number of the newest complete flow, 0 = none
  std::uint64_t segment_size;     // bytes of the whole segment
  std::uint64_t data_bytes;       // bytes of flow data in each slot: grid_width * grid_height * 8
  std::uint32_t writer_pid;
  std::uint32_t reserved0;
  std::uint64_t created_realtime_ns;  // CLOCK_REALTIME when the segment was created
  std::uint8_t reserved[32];
};

// At the start of each slot, followed by the flow data at slot_header_size.
struct SlotHeader {
  std::uint64_t sequence;    // atomic seqlock word: 2n-1 while flow n is written, 2n once complete
  std::uint64_t from_frame;  // frame numbers of the two frames (counted by the `neuflow` element)
  std::uint64_t to_frame;
  std::uint64_t from_pts_ns;  // their timestamps, kNoTimestamp when unknown
  std::uint64_t to_pts_ns;
  std::uint64_t inference_ns;         // wall time of the computation
  std::uint64_t written_realtime_ns;  // CLOCK_REALTIME when the writer published the flow
  std::uint32_t grid_width;           // equal to the header's
  std::uint32_t grid_height;
  std::uint32_t frame_width;  // the frame the grid covers
  std::uint32_t frame_height;
  std::uint32_t model_width;  // the size the network ran at
  std::uint32_t model_height;
  std::uint32_t iters_s16;  // refinement iterations at 1/16 and 1/8
  std::uint32_t iters_s8;
  std::uint32_t crc32;  // CRC-32 (zlib's, polynomial 0xEDB88320 reflected) of the data bytes
  std::uint32_t reserved0;
  std::uint64_t data_bytes;
  std::uint8_t reserved[24];
};

// The offsets are the format (docs/shm-ring.md lists them); these pin the structs to them.
static_assert(sizeof(RingHeader) == 128 && sizeof(SlotHeader) == 128);
static_assert(offsetof(RingHeader, version) == 8 && offsetof(RingHeader, header_size) == 12 &&
              offsetof(RingHeader, slot_count) == 16 && offsetof(RingHeader, slot_header_size) == 20 &&
              offsetof(RingHeader, slot_stride) == 24 && offsetof(RingHeader, grid_width) == 32 &&
              offsetof(RingHeader, grid_height) == 36 && offsetof(RingHeader, value_layout) == 40 &&
              offsetof(RingHeader, state) == 44 && offsetof(RingHeader, generation) == 48 &&
              offsetof(RingHeader, flows_published) == 56 && offsetof(RingHeader, segment_size) == 64 &&
              offsetof(RingHeader, data_bytes) == 72 && offsetof(RingHeader, writer_pid) == 80 &&
              offsetof(RingHeader, created_realtime_ns) == 88 && offsetof(RingHeader, reserved) == 96);
static_assert(offsetof(SlotHeader, sequence) == 0 && offsetof(SlotHeader, from_frame) == 8 &&
              offsetof(SlotHeader, to_frame) == 16 && offsetof(SlotHeader, from_pts_ns) == 24 &&
              offsetof(SlotHeader, to_pts_ns) == 32 && offsetof(SlotHeader, inference_ns) == 40 &&
              offsetof(SlotHeader, written_realtime_ns) == 48 && offsetof(SlotHeader, grid_width) == 56 &&
              offsetof(SlotHeader, grid_height) == 60 && offsetof(SlotHeader, frame_width) == 64 &&
              offsetof(SlotHeader, frame_height) == 68 && offsetof(SlotHeader, model_width) == 72 &&
              offsetof(SlotHeader, model_height) == 76 && offsetof(SlotHeader, iters_s16) == 80 &&
              offsetof(SlotHeader, iters_s8) == 84 && offsetof(SlotHeader, crc32) == 88 &&
              offsetof(SlotHeader, data_bytes) == 96 && offsetof(SlotHeader, reserved) == 104);

inline constexpr std::size_t kStateOffset = offsetof(RingHeader, state);
inline constexpr std::size_t kPublishedOffset = offsetof(RingHeader, flows_published);
inline constexpr std::size_t kSequenceOffset = offsetof(SlotHeader, sequence);

// Atomic access to a field of a mapped segment. The mapping is shared with another process,
// so the field must be accessed through lock-free atomics (asserted above); atomic_ref needs
// a non-const object, but loads never write, so a read-only mapping is fine.
template <class T>
inline std::atomic_ref<T> atomic_field(const std::byte *base, std::size_t offset) {
  return std::atomic_ref<T>(*static_cast<T *>(static_cast<void *>(const_cast<std::byte *>(base + offset))));
}

// ---------------------------------------------------------------------------------------
// CRC-32 as zlib computes it (the IEEE 802.3 polynomial, reflected: 0xEDB88320; initial
// value and final xor 0xFFFFFFFF), so that Python's zlib.crc32(data) gives the same value.
namespace detail {
using CrcTables = std::array<std::array<std::uint32_t, 256>, 8>;
constexpr CrcTables make_crc_tables() {
  CrcTables t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  // Slicing-by-8: table k advances a byte through k more zero bytes.
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xffu];
  }
  return t;
}
inline constexpr CrcTables kCrcTables = make_crc_tables();
}  // namespace detail

// Continues `crc` (0 to start) over `size` bytes.
inline std::uint32_t crc32(const void *data, std::size_t size, std::uint32_t crc = 0) {
  const auto &t = detail::kCrcTables;
  const auto *p = static_cast<const unsigned char *>(data);
  crc = ~crc;
  for (; size >= 8; size -= 8, p += 8) {
    std::uint32_t lo, hi;
    std::memcpy(&lo, p, 4);
    std::memcpy(&hi, p + 4, 4);
    lo ^= crc;
    crc = t[7][lo & 0xffu] ^ t[6][(lo >> 8) & 0xffu] ^ t[5][(lo >> 16) & 0xffu] ^ t[4][lo >> 24] ^ t[3][hi & 0xffu] ^
          t[2][(hi >> 8) & 0xffu] ^ t[1][(hi >> 16) & 0xffu] ^ t[0][hi >> 24];
  }
  for (; size > 0; --size) crc = t[0][(crc ^ *p++) & 0xffu] ^ (crc >> 8);
  return ~crc;
}

// ---------------------------------------------------------------------------------------

// One flow's metadata, copied out of its slot together with the data.
struct FlowInfo {
  std::uint64_t sequence = 0;  // 1 for the first flow of the segment, then consecutive
  std::uint64_t from_frame = 0, to_frame = 0;
  std::uint64_t from_pts_ns = kNoTimestamp, to_pts_ns = kNoTimestamp;
  std::uint64_t inference_ns = 0;
  std::uint64_t written_realtime_ns = 0;
  std::uint32_t grid_width = 0, grid_height = 0;
  std::uint32_t frame_width = 0, frame_height = 0;
  std::uint32_t model_width = 0, model_height = 0;
  std::uint32_t iters_s16 = 0, iters_s8 = 0;
  std::uint32_t crc32 = 0;
  std::uint64_t data_bytes = 0;
};

// Whether `uv` (as filled by a read) matches the checksum the writer stored.
inline bool verify(std::span<const float> uv, const FlowInfo &info) {
  return uv.size_bytes() >= info.data_bytes &&
         crc32(uv.data(), static_cast<std::size_t>(info.data_bytes)) == info.crc32;
}

enum class ReadStatus {
  ok,             // the flow was copied whole
  not_published,  // no such flow yet (or, for latest(), none at all)
  overwritten,    // the writer has reused the slot for a newer flow: too late
  torn,           // every attempt overlapped a write (bounded retries ran out); nothing usable copied
};

inline const char *to_string(ReadStatus s) {
  switch (s) {
    case ReadStatus::ok: return "ok";
    case ReadStatus::not_published: return "not published";
    case ReadStatus::overwritten: return "overwritten";
    case ReadStatus::torn: return "torn";
  }
  return "?";
}

class RingError : public std::runtime_error {
 public:
  enum class Kind {
    no_such_segment,      // nothing under that name: the writer is not running (yet)
    permission_denied,    // the segment exists but this user may not read it
    not_ready,            // the writer is creating it or has not published its first flow: retry
    bad_magic,            // the segment is something else than a flow ring
    unsupported_version,  // a layout this reader does not know
    bad_layout,           // header fields that contradict each other or the segment size
    system,               // another system call failure
  };
  RingError(Kind kind, const std::string &message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }
  // Whether waiting and opening again may succeed.
  bool retryable() const { return kind_ == Kind::no_such_segment || kind_ == Kind::not_ready; }

 private:
  Kind kind_;
};

// Reads one flow ring. Opening maps the segment read-only; the reader never writes to it and
// never makes the writer wait. Not thread-safe: use one reader per thread.
class FlowRingReader {
 public:
  // Throws RingError naming the segment and what was wrong.
  explicit FlowRingReader(std::string name) : name_(std::move(name)) { map(); }
  ~FlowRingReader() { unmap(); }
  FlowRingReader(const FlowRingReader &) = delete;
  FlowRingReader &operator=(const FlowRingReader &) = delete;
  FlowRingReader(FlowRingReader &&other) noexcept { *this = std::move(other); }
  FlowRingReader &operator=(FlowRingReader &&other) noexcept {
    if (this != &other) {
      unmap();
      name_ = std::move(other.name_);
      base_ = std::exchange(other.base_, nullptr);
      size_ = std::exchange(other.size_, 0);
      header_ = other.header_;
    }
    return *this;
  }

  const std::string &name() const { return name_; }
  std::uint32_t width() const { return header_.grid_width; }
  std::uint32_t height() const { return header_.grid_height; }
  std::uint32_t slot_count() const { return header_.slot_count; }
  std::uint64_t generation() const { return header_.generation; }
  std::uint32_t writer_pid() const { return header_.writer_pid; }
  // Floats in one flow: width * height * 2.
  std::size_t values_per_flow() const { return static_cast<std::size_t>(header_.data_bytes / sizeof(float)); }

  // The sequence number of the newest complete flow, 0 when none has been published. Flows
  // published() - slot_count() + 1 ... published() are in the ring.
  std::uint64_t published() const {
    return atomic_field<std::uint64_t>(base_, kPublishedOffset).load(std::memory_order_acquire);
  }

  // True once the writer has stopped or replaced this segment (its grid size changed): the
  // mapping stays readable with the flows it held, but new flows go to a new segment under
  // the same name, which reopen() maps.
  bool replaced() const {
    return atomic_field<std::uint32_t>(base_, kStateOffset).load(std::memory_order_acquire) !=
           static_cast<std::uint32_t>(SegmentState::live);
  }

  // Maps the segment now under the name (after replaced()); throws RingError as the
  // constructor does, keeping the current mapping in that case.
  void reopen() {
    FlowRingReader fresh(name_);
    *this = std::move(fresh);
  }

  // Copies flow `sequence` into `uv` (at least values_per_flow() floats) and its metadata into
  // `info` with the seqlock protocol: read the slot's sequence word, copy, read it again; equal
  // and even means nothing was written in between. Retries a copy that overlapped a write at
  // most `max_attempts` times. `uv` and `info` hold the flow only when ok is returned.
  ReadStatus read(std::uint64_t sequence, std::span<float> uv, FlowInfo &info, int max_attempts = 16) const {
    if (uv.size() < values_per_flow()) {
      throw std::invalid_argument("flow ring \"" + name_ + "\": the buffer holds " + std::to_string(uv.size()) +
                                  " floats, a flow needs " + std::to_string(values_per_flow()));
    }
    if (sequence == 0) return ReadStatus::not_published;
    const std::byte *slot = base_ + header_.header_size + ((sequence - 1) % header_.slot_count) * header_.slot_stride;
    auto word = atomic_field<std::uint64_t>(slot, kSequenceOffset);
    const std::uint64_t wanted = 2 * sequence;
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
      const std::uint64_t before = word.load(std::memory_order_acquire);
      // 2n-1 (odd) while flow n is written, 2n once it is complete: the flow in the slot is
      // (before + 1) / 2, and it is ours only when before == 2 * sequence.
      if (before > wanted) return ReadStatus::overwritten;
      if (before < wanted) return ReadStatus::not_published;
      SlotHeader slot_header;
      std::memcpy(&slot_header, slot, sizeof slot_header);
      std::memcpy(uv.data(), slot + header_.slot_header_size, static_cast<std::size_t>(header_.data_bytes));
      // Orders the copies before the second read of the word: if any byte came from a
      // later write, that read sees the word the writer changed before writing it.
      std::atomic_thread_fence(std::memory_order_acquire);
      if (word.load(std::memory_order_relaxed) == before) {
        fill(info, slot_header, sequence);
        return ReadStatus::ok;
      }
      if (attempt > 2) std::this_thread::yield();
    }
    return ReadStatus::torn;
  }

  // Copies the newest flow; retries when the writer overtakes the copy.
  ReadStatus latest(std::span<float> uv, FlowInfo &info, int max_attempts = 16) const {
    ReadStatus status = ReadStatus::not_published;
    for (int attempt = 0; attempt < max_attempts; ++attempt) {
      const std::uint64_t newest = published();
      if (newest == 0) return ReadStatus::not_published;
      status = read(newest, uv, info, max_attempts);
      if (status == ReadStatus::ok || status == ReadStatus::torn) return status;
    }
    return status == ReadStatus::overwritten ? ReadStatus::torn : status;
  }

 private:
  [[noreturn]] void fail(RingError::Kind kind, const std::string &what) const {
    throw RingError(kind, "flow ring \"" + name_ + "\": " + what);
  }

  static std::string errno_text(int err) { return std::generic_category().message(err); }

  void map() {
    if (name_.size() < 2 || name_[0] != '/' || name_.find('/', 1) != std::string::npos) {
      fail(RingError::Kind::no_such_segment, "not a shared-memory name: expected \"/name\" with no other '/'");
    }
    const int fd = ::shm_open(name_.c_str(), O_RDONLY | O_CLOEXEC, 0);
    if (fd < 0) {
      const int err = errno;
      if (err == ENOENT)
        fail(RingError::Kind::no_such_segment, "no such shared-memory segment (is the writer running?)");
      if (err == EACCES) {
        fail(RingError::Kind::permission_denied,
             "permission denied (the writer's shm-mode is 0640 by default: run the reader as the writer's user or "
             "in its group, which is 'neuflow' under neuflowd's systemd units, or give the writer shm-mode=0644)");
      }
      fail(RingError::Kind::system, "cannot open: " + errno_text(err));
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      const int err = errno;
      ::close(fd);
      fail(RingError::Kind::system, "cannot stat: " + errno_text(err));
    }
    const auto size = static_cast<std::uint64_t>(st.st_size);
    if (size < sizeof(RingHeader)) {
      ::close(fd);
      fail(RingError::Kind::not_ready, "segment is " + std::to_string(size) +
                                           " bytes, less than a flow ring header (the writer is still creating it, "
                                           "or it is not a flow ring)");
    }
    void *p = ::mmap(nullptr, static_cast<std::size_t>(size), PROT_READ, MAP_SHARED, fd, 0);
    const int err = errno;
    ::close(fd);  // the mapping keeps the segment alive
    if (p == MAP_FAILED) fail(RingError::Kind::system, "cannot map: " + errno_text(err));
    base_ = static_cast<const std::byte *>(p);
    size_ = static_cast<std::size_t>(size);
    try {
      validate(size);
    } catch (...) {
      unmap();
      throw;
    }
  }

  void validate(std::uint64_t size) {
    // `state` first: once it reads live (acquire), every other header field is complete.
    const auto state = atomic_field<std::uint32_t>(base_, kStateOffset).load(std::memory_order_acquire);
    std::memcpy(&header_, base_, sizeof header_);
    const bool magic_ok = std::memcmp(header_.magic, kMagic.data(), kMagic.size()) == 0;
    if (state != static_cast<std::uint32_t>(SegmentState::live)) {
      bool blank = true;  // created, not yet filled in
      for (char c : header_.magic) blank = blank && c == 0;
      if (!magic_ok && !blank) fail(RingError::Kind::bad_magic, "not a neuflow flow ring (bad magic)");
      if (state == static_cast<std::uint32_t>(SegmentState::closed)) {
        fail(RingError::Kind::not_ready, "the writer has closed this segment (it is stopping or replacing it)");
      }
      fail(RingError::Kind::not_ready, "the writer has not published its first flow yet");
    }
    if (!magic_ok) fail(RingError::Kind::bad_magic, "not a neuflow flow ring (bad magic)");
    if (header_.version != kLayoutVersion) {
      fail(RingError::Kind::unsupported_version, "layout version " + std::to_string(header_.version) +
                                                     ", this reader supports version " +
                                                     std::to_string(kLayoutVersion));
    }
    const auto &h = header_;
    const std::uint64_t cells = std::uint64_t{h.grid_width} * h.grid_height;
    bool ok = h.header_size >= sizeof(RingHeader) && h.slot_header_size >= sizeof(SlotHeader) &&
              h.slot_header_size % 8 == 0 && h.header_size % 8 == 0 && h.slot_stride % 8 == 0 && h.slot_count >= 1 &&
              h.value_layout == kValueLayoutF32UV && cells > 0 && h.data_bytes == cells * 2 * sizeof(float) &&
              h.slot_stride >= h.slot_header_size + h.data_bytes && h.segment_size == size;
    // header_size + slot_count * slot_stride <= size, without overflow.
    ok = ok && h.header_size <= size && h.slot_stride <= (size - h.header_size) / h.slot_count;
    if (!ok) {
      fail(RingError::Kind::bad_layout,
           "inconsistent header (grid " + std::to_string(h.grid_width) + "x" + std::to_string(h.grid_height) + ", " +
               std::to_string(h.slot_count) + " slots of " + std::to_string(h.slot_stride) + " bytes, value layout " +
               std::to_string(h.value_layout) + ", segment of " + std::to_string(size) + " bytes)");
    }
  }

  static void fill(FlowInfo &info, const SlotHeader &s, std::uint64_t sequence) {
    info.sequence = sequence;
    info.from_frame = s.from_frame;
    info.to_frame = s.to_frame;
    info.from_pts_ns = s.from_pts_ns;
    info.to_pts_ns = s.to_pts_ns;
    info.inference_ns = s.inference_ns;
    info.written_realtime_ns = s.written_realtime_ns;
    info.grid_width = s.grid_width;
    info.grid_height = s.grid_height;
    info.frame_width = s.frame_width;
    info.frame_height = s.frame_height;
    info.model_width = s.model_width;
    info.model_height = s.model_height;
    info.iters_s16 = s.iters_s16;
    info.iters_s8 = s.iters_s8;
    info.crc32 = s.crc32;
    info.data_bytes = s.data_bytes;
  }

  void unmap() {
    if (base_) ::munmap(const_cast<std::byte *>(base_), size_);
    base_ = nullptr;
    size_ = 0;
  }

  std::string name_;
  const std::byte *base_ = nullptr;
  std::size_t size_ = 0;
  RingHeader header_{};
};

}  // namespace neuflow::ring

#endif  // NEUFLOW_FLOW_RING_HPP
