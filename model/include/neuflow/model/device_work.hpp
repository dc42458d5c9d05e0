#pragma once
// What a GPU was asked to do for a pass, counted from the shapes of the commands when they were
// recorded, not measured on the device: the same on every GPU and on lavapipe, so a test can
// hold it to a budget and a run without a GPU can say what a GPU would be given.
#include <cstdint>
#include <string>
#include <vector>

namespace neuflow::model {

// One command: a compute dispatch, or a buffer copy (kernel "copy").
struct DeviceCommand {
  std::string kernel;  // the shader ("conv2d", "matmul", ...) or "copy"
  std::string stage;   // the named stage it belongs to (stage_observer.hpp), "" after the last
  std::uint64_t workgroups = 0;
  // The tensors it reads and writes, each once: what a kernel with perfect reuse would move.
  std::uint64_t bytes_read = 0, bytes_written = 0;
  std::uint64_t multiply_adds = 0;  // a transform-domain algorithm counts what it computes
  bool after_barrier = false;       // waits for the commands before it (a pipeline barrier)
};

struct DeviceWork {
  int dispatches = 0;
  int copies = 0;
  int barriers = 0;  // pipeline barriers between commands (one before a pass's first command)
  int timestamps = 0;
  int submissions = 0;
  int host_waits = 0;
  std::vector<DeviceCommand> commands;  // in recording order

  std::uint64_t bytes_read() const {
    std::uint64_t n = 0;
    for (const auto& c : commands) n += c.bytes_read;
    return n;
  }
  std::uint64_t bytes_written() const {
    std::uint64_t n = 0;
    for (const auto& c : commands) n += c.bytes_written;
    return n;
  }
  std::uint64_t multiply_adds() const {
    std::uint64_t n = 0;
    for (const auto& c : commands) n += c.multiply_adds;
    return n;
  }
  DeviceWork& operator+=(const DeviceWork& other) {
    dispatches += other.dispatches;
    copies += other.copies;
    barriers += other.barriers;
    timestamps += other.timestamps;
    submissions += other.submissions;
    host_waits += other.host_waits;
    commands.insert(commands.end(), other.commands.begin(), other.commands.end());
    return *this;
  }
};

}  // namespace neuflow::model
