#include "flow_ring_writer.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <optional>
#include <system_error>
#include <utility>

#include "neuflow/flow_ring.hpp"

namespace neuflow::gst {

namespace {

namespace ring = neuflow::ring;

// Slots start on cache-line boundaries, so that one slot's writes never share a line with
// the next slot's sequence word that readers are polling.
constexpr std::uint64_t kSlotAlignment = 64;
// A flow grid larger than this per slot is a bug upstream rather than a flow.
constexpr std::uint64_t kMaxDataBytes = std::uint64_t{1} << 30;

std::string errno_text(int err) { return std::generic_category().message(err); }

std::uint64_t realtime_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000u + static_cast<std::uint64_t>(ts.tv_nsec);
}

std::atomic_ref<std::uint32_t> state_of(std::byte *base) {
  return ring::atomic_field<std::uint32_t>(base, ring::kStateOffset);
}

// Whether the segment behind `fd` is a flow ring, and its generation.
std::optional<std::uint64_t> ring_generation(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0 || static_cast<std::uint64_t>(st.st_size) < sizeof(ring::RingHeader)) return std::nullopt;
  ring::RingHeader header{};
  if (::pread(fd, &header, sizeof header, 0) != static_cast<ssize_t>(sizeof header)) return std::nullopt;
  if (std::memcmp(header.magic, ring::kMagic.data(), ring::kMagic.size()) != 0) return std::nullopt;
  return header.generation;
}

// Marks a ring segment closed so that readers still mapping it look for its successor.
void mark_closed(int fd) {
  struct stat st {};
  if (::fstat(fd, &st) != 0 || static_cast<std::uint64_t>(st.st_size) < sizeof(ring::RingHeader)) return;
  void *p = ::mmap(nullptr, sizeof(ring::RingHeader), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  if (p == MAP_FAILED) return;
  state_of(static_cast<std::byte *>(p))
      .store(static_cast<std::uint32_t>(ring::SegmentState::closed), std::memory_order_release);
  ::munmap(p, sizeof(ring::RingHeader));
}

}  // namespace

std::optional<std::string> check_flow_ring_name(std::string_view name) {
  std::string problem = ring::segment_name_problem(name);
  return problem.empty() ? std::nullopt : std::optional<std::string>(std::move(problem));
}

std::optional<std::string> check_flow_ring_mode(mode_t mode) {
  std::string problem = ring::segment_mode_problem(static_cast<unsigned>(mode));
  return problem.empty() ? std::nullopt : std::optional<std::string>(std::move(problem));
}

FlowRingWriter::FlowRingWriter(std::string name, std::uint32_t slots, std::uint64_t first_generation, mode_t mode)
    : name_(std::move(name)), slots_(slots), mode_(mode), generation_(first_generation) {
  if (auto problem = check_flow_ring_name(name_)) {
    throw FlowRingError("invalid shared-memory name \"" + name_ + "\": " + *problem);
  }
  if (auto problem = check_flow_ring_mode(mode_)) {
    char octal[16];
    std::snprintf(octal, sizeof octal, "%04o", static_cast<unsigned>(mode_));
    throw FlowRingError("flow ring \"" + name_ + "\": invalid mode " + octal + ": " + *problem);
  }
  if (slots_ == 0) throw FlowRingError("flow ring \"" + name_ + "\": needs at least one slot");
  segment_ = create_segment(sizeof(ring::RingHeader));
  initialize_header(0, 0, 0, 0, static_cast<std::uint32_t>(ring::SegmentState::initializing));
}

FlowRingWriter::~FlowRingWriter() { retire(segment_); }

void FlowRingWriter::fail(const std::string &what, int err) const {
  throw FlowRingError("flow ring \"" + name_ + "\": " + what + (err ? ": " + errno_text(err) : std::string()));
}

FlowRingWriter::Segment FlowRingWriter::create_segment(std::uint64_t size) {
  // An existing segment is either left by a writer that died (nobody holds its lock) or in
  // use by another writer (its lock is held): replace the first, refuse the second.
  if (const int old = ::shm_open(name_.c_str(), O_RDWR | O_CLOEXEC, 0); old >= 0) {
    if (::flock(old, LOCK_EX | LOCK_NB) != 0) {
      const int err = errno;
      ::close(old);
      if (err == EWOULDBLOCK) fail("already in use by another writer (another neuflowshmsink with this shm-name?)", 0);
      fail("cannot lock the existing segment", err);
    }
    if (const auto stale_generation = ring_generation(old)) {
      if (*stale_generation >= generation_) generation_ = *stale_generation + 1;
      mark_closed(old);
    }
    ::shm_unlink(name_.c_str());
    ::close(old);
  } else if (errno != ENOENT) {
    const int err = errno;
    fail(err == EACCES ? "an existing segment of that name belongs to another user" : "cannot open", err);
  }

  // Always a new segment (O_EXCL), never a resized old one: readers mapping the old one keep
  // a valid mapping instead of faulting on pages that a shrink took away.
  Segment s;
  s.fd = ::shm_open(name_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, mode_);
  if (s.fd < 0) {
    const int err = errno;
    if (err == EEXIST) fail("another writer created it at the same moment", 0);
    fail("cannot create the shared-memory segment", err);
  }
  auto cleanup_fail = [&](const std::string &what, int err) {
    ::close(s.fd);
    ::shm_unlink(name_.c_str());
    fail(what, err);
  };
  if (::flock(s.fd, LOCK_EX | LOCK_NB) != 0) cleanup_fail("cannot lock the new segment", errno);
  // shm_open applies the umask to the mode; the documented mode is the one readers rely on.
  if (::fchmod(s.fd, mode_) != 0) cleanup_fail("cannot set the segment's mode", errno);
  if (::ftruncate(s.fd, static_cast<off_t>(size)) != 0) {
    cleanup_fail("cannot size the segment to " + std::to_string(size) + " bytes", errno);
  }
  // tmpfs allocates pages when they are first touched; reserving them now turns a full
  // /dev/shm into this error instead of a SIGBUS in the middle of a publish.
  int err = 0;
  do {
    err = ::posix_fallocate(s.fd, 0, static_cast<off_t>(size));
  } while (err == EINTR);
  if (err != 0) {
    cleanup_fail("cannot reserve " + std::to_string(size) + " bytes of shared memory (is /dev/shm full?)", err);
  }
  void *p = ::mmap(nullptr, static_cast<std::size_t>(size), PROT_READ | PROT_WRITE, MAP_SHARED, s.fd, 0);
  if (p == MAP_FAILED) cleanup_fail("cannot map the segment", errno);
  struct stat st {};
  if (::fstat(s.fd, &st) != 0) {
    ::munmap(p, static_cast<std::size_t>(size));
    cleanup_fail("cannot stat the segment", errno);
  }
  s.base = static_cast<std::byte *>(p);
  s.size = static_cast<std::size_t>(size);
  s.dev = st.st_dev;
  s.ino = st.st_ino;
  return s;
}

void FlowRingWriter::initialize_header(std::uint32_t width, std::uint32_t height, std::uint64_t stride,
                                       std::uint64_t data_bytes, std::uint32_t state) {
  ring::RingHeader h{};
  std::memcpy(h.magic, ring::kMagic.data(), ring::kMagic.size());
  h.version = ring::kLayoutVersion;
  h.header_size = sizeof(ring::RingHeader);
  h.slot_count = slots_;
  h.slot_header_size = sizeof(ring::SlotHeader);
  h.slot_stride = stride;
  h.grid_width = width;
  h.grid_height = height;
  h.value_layout = ring::kValueLayoutF32UV;
  h.state = static_cast<std::uint32_t>(ring::SegmentState::initializing);
  h.generation = generation_;
  h.flows_published = 0;
  h.segment_size = segment_.size;
  h.data_bytes = data_bytes;
  h.writer_pid = static_cast<std::uint32_t>(::getpid());
  h.created_realtime_ns = realtime_ns();
  std::memcpy(segment_.base, &h, sizeof h);
  // Readers check `state` first; the release store publishes every field written above.
  state_of(segment_.base).store(state, std::memory_order_release);
}

void FlowRingWriter::unlink_if_ours(const Segment &segment) const {
  // Someone may have removed the name and another writer taken it since.
  if (const int fd = ::shm_open(name_.c_str(), O_RDONLY | O_CLOEXEC, 0); fd >= 0) {
    struct stat st {};
    const bool ours = ::fstat(fd, &st) == 0 && st.st_dev == segment.dev && st.st_ino == segment.ino;
    ::close(fd);
    if (ours) ::shm_unlink(name_.c_str());
  }
}

void FlowRingWriter::release(Segment &segment) {
  if (segment.base) ::munmap(segment.base, segment.size);
  if (segment.fd >= 0) ::close(segment.fd);  // releases the lock
  segment = Segment{};
}

void FlowRingWriter::retire(Segment &segment) {
  if (!segment.base) return;
  state_of(segment.base).store(static_cast<std::uint32_t>(ring::SegmentState::closed), std::memory_order_release);
  unlink_if_ours(segment);
  release(segment);
}

void FlowRingWriter::replace(std::uint32_t width, std::uint32_t height) {
  const std::uint64_t data_bytes = std::uint64_t{width} * height * 2 * sizeof(float);  // checked by publish()
  const std::uint64_t stride =
      (sizeof(ring::SlotHeader) + data_bytes + kSlotAlignment - 1) / kSlotAlignment * kSlotAlignment;
  const std::uint64_t size = sizeof(ring::RingHeader) + stride * slots_;

  // The old segment stays locked until the new one exists, so that no other writer takes
  // the name in between; readers mapping it see it closed and re-open the name.
  Segment old = std::exchange(segment_, Segment{});
  if (old.base) {
    state_of(old.base).store(static_cast<std::uint32_t>(ring::SegmentState::closed), std::memory_order_release);
    unlink_if_ours(old);
  }
  width_ = height_ = 0;  // until the new segment exists: a failed replace is retried in full
  ++generation_;
  try {
    segment_ = create_segment(size);
  } catch (...) {
    release(old);
    throw;
  }
  release(old);

  width_ = width;
  height_ = height;
  stride_ = stride;
  data_bytes_ = data_bytes;
  published_ = 0;
  initialize_header(width, height, stride, data_bytes, static_cast<std::uint32_t>(ring::SegmentState::live));
}

void FlowRingWriter::publish(std::uint32_t width, std::uint32_t height, const FlowRecord &record,
                             std::span<const float> uv) {
  // Checked before any replacement: bad input leaves the ring as it was.
  const std::uint64_t cells = std::uint64_t{width} * height;  // cannot overflow: two 32-bit factors
  if (width == 0 || height == 0 || cells > kMaxDataBytes / (2 * sizeof(float))) {
    fail("a flow grid of " + std::to_string(width) + "x" + std::to_string(height) + " does not fit a slot (at most " +
             std::to_string(kMaxDataBytes >> 20) + " MiB of vectors)",
         0);
  }
  const std::uint64_t needed = cells * 2 * sizeof(float);
  if (uv.size_bytes() < needed) {
    fail("a flow of " + std::to_string(width) + "x" + std::to_string(height) + " needs " + std::to_string(needed) +
             " bytes of vectors, got " + std::to_string(uv.size_bytes()),
         0);
  }
  if (width != width_ || height != height_) replace(width, height);

  const std::uint64_t sequence = published_ + 1;
  std::byte *slot = segment_.base + sizeof(ring::RingHeader) + ((sequence - 1) % slots_) * stride_;

  ring::SlotHeader h{};
  h.from_frame = record.from_frame;
  h.to_frame = record.to_frame;
  h.from_pts_ns = record.from_pts_ns;
  h.to_pts_ns = record.to_pts_ns;
  h.inference_ns = record.inference_ns;
  h.written_realtime_ns = realtime_ns();
  h.grid_width = width;
  h.grid_height = height;
  h.frame_width = record.frame_width;
  h.frame_height = record.frame_height;
  h.model_width = record.model_width;
  h.model_height = record.model_height;
  h.iters_s16 = record.iters_s16;
  h.iters_s8 = record.iters_s8;
  // Computed from the source, before the slot is opened, to keep the odd window short.
  h.crc32 = static_cast<std::uint32_t>(::crc32_z(::crc32_z(0, nullptr, 0), reinterpret_cast<const Bytef *>(uv.data()),
                                                 static_cast<z_size_t>(data_bytes_)));
  h.data_bytes = data_bytes_;

  // Seqlock write: odd word, release fence, contents, even word (release). A reader whose
  // copy overlapped any of the contents sees the word change and discards the copy.
  auto word = ring::atomic_field<std::uint64_t>(slot, ring::kSequenceOffset);
  word.store(2 * sequence - 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  std::memcpy(slot + sizeof h.sequence, reinterpret_cast<const std::byte *>(&h) + sizeof h.sequence,
              sizeof h - sizeof h.sequence);
  std::memcpy(slot + sizeof(ring::SlotHeader), uv.data(), static_cast<std::size_t>(data_bytes_));
  word.store(2 * sequence, std::memory_order_release);
  ring::atomic_field<std::uint64_t>(segment_.base, ring::kPublishedOffset).store(sequence, std::memory_order_release);
  published_ = sequence;
}

}  // namespace neuflow::gst
