// The shared-memory ring reader (plugins/include/neuflow/flow_ring.hpp) on a hostile segment:
// the input becomes the whole segment. RingError is the documented failure of opening; once
// open, reading the newest flows must stay inside the mapping (ASan) and return a status, and
// what it reports must fit the segment it validated.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "neuflow/flow_ring.hpp"

namespace {

// A segment of this process's own, holding the input.
class Segment {
 public:
  Segment() : name_("/neuflow-fuzz-ring-" + std::to_string(::getpid())) {}
  ~Segment() { ::shm_unlink(name_.c_str()); }
  Segment(const Segment&) = delete;
  Segment& operator=(const Segment&) = delete;

  bool write(const std::uint8_t* data, std::size_t size) {
    const int fd = ::shm_open(name_.c_str(), O_CREAT | O_RDWR | O_TRUNC, 0600);
    if (fd < 0) return false;
    bool ok = ::ftruncate(fd, static_cast<off_t>(size)) == 0;
    for (std::size_t done = 0; ok && done < size;) {
      const ssize_t n = ::pwrite(fd, data + done, size - done, static_cast<off_t>(done));
      ok = n > 0;
      done += ok ? static_cast<std::size_t>(n) : 0;
    }
    ::close(fd);
    return ok;
  }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Segment segment;
  if (!segment.write(data, size)) return 0;  // the machine's problem, not the reader's
  try {
    const neuflow::ring::FlowRingReader reader(segment.name());
    const std::size_t values = reader.values_per_flow();
    if (values * sizeof(float) > size) {
      neuflow::fuzz::invariant_failed("ring_reader", "a flow larger than the segment it was validated against");
    }
    std::vector<float> uv(values);
    neuflow::ring::FlowInfo info;
    const std::uint64_t newest = reader.published();
    for (std::uint64_t sequence = newest; sequence + 3 > newest && sequence > 0; --sequence) {
      if (reader.read(sequence, uv, info, 2) == neuflow::ring::ReadStatus::ok && info.sequence != sequence) {
        neuflow::fuzz::invariant_failed("ring_reader", "a flow read under another sequence number");
      }
    }
    if (reader.latest(uv, info, 2) == neuflow::ring::ReadStatus::ok) (void)neuflow::ring::verify(uv, info);
    (void)reader.replaced();
  } catch (const neuflow::ring::RingError&) {
  } catch (...) {
    neuflow::fuzz::unexpected_exception("ring_reader");
  }
  return 0;
}
