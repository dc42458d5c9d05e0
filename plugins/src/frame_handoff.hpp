#pragma once
// The ordered hand-off between two threads of the `neuflow` element: the streaming thread
// gives frames and serialized events to the inference worker, and the inference worker gives
// its results to the thread that pushes them downstream. No GStreamer in here: the element
// instantiates it with its own item type, and the tests with plain values.
//
// Frames are bounded: a producer either replaces the frames still waiting (newest wins: a
// live source never waits for inference) or waits while `capacity` frames are waiting (back
// pressure: every frame is processed). Other items (events) are never dropped and never wait,
// and keep their place between the frames. Flushing wakes every waiter and hands back what
// was waiting; a failure reported by the consumer (downstream refused a buffer) makes the
// producers' pushes fail until the next flush stops.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

namespace neuflow::gst {

template <typename T>
class FrameHandoff {
 public:
  enum class Policy { newest_wins, back_pressure };
  enum class Result { queued, flushing, failed };

  struct Entry {
    T value;
    bool frame = false;
  };

  // `capacity`: frames that may wait under back pressure (at least 1).
  explicit FrameHandoff(std::size_t capacity) : capacity_(capacity < 1 ? 1 : capacity) {}
  FrameHandoff(const FrameHandoff&) = delete;
  FrameHandoff& operator=(const FrameHandoff&) = delete;

  // Queues a frame. Under newest_wins the frames still waiting are taken out and appended to
  // `dropped`, oldest first (they never reach the consumer; the caller releases them); under
  // back_pressure this waits while `capacity` frames wait. Unless queued, the frame is left
  // with the caller.
  Result push_frame(T& frame, Policy policy, std::vector<T>* dropped = nullptr) {
    std::unique_lock lock(mutex_);
    if (policy == Policy::newest_wins) {
      for (auto it = entries_.begin(); it != entries_.end();) {
        if (!it->frame) {
          ++it;
          continue;
        }
        if (dropped) dropped->push_back(std::move(it->value));
        it = entries_.erase(it);
        --frames_;
      }
    } else {
      not_full_.wait(lock, [&] { return flushing_ || failure_ || frames_ < capacity_; });
    }
    if (flushing_) return Result::flushing;
    if (failure_) return Result::failed;
    entries_.push_back(Entry{std::move(frame), true});
    ++frames_;
    lock.unlock();
    not_empty_.notify_one();
    return Result::queued;
  }

  // Queues anything else, in order; never waits. Unless queued, it is left with the caller.
  Result push_other(T& value) {
    {
      const std::lock_guard lock(mutex_);
      if (flushing_) return Result::flushing;
      entries_.push_back(Entry{std::move(value), false});
    }
    not_empty_.notify_one();
    return Result::queued;
  }

  // The consumer's next entry, waiting for one; nothing once flushing. The consumer is busy
  // with it until done().
  std::optional<Entry> take() {
    std::unique_lock lock(mutex_);
    not_empty_.wait(lock, [&] { return flushing_ || !entries_.empty(); });
    if (flushing_) return std::nullopt;
    Entry entry = std::move(entries_.front());
    entries_.pop_front();
    if (entry.frame) --frames_;
    busy_ = true;
    lock.unlock();
    not_full_.notify_all();
    return entry;
  }

  // Whether the consumer's next entry is a frame that is already waiting (never waits).
  bool frame_waiting() const {
    const std::lock_guard lock(mutex_);
    return !flushing_ && !entries_.empty() && entries_.front().frame;
  }

  void done() {
    {
      const std::lock_guard lock(mutex_);
      busy_ = false;
    }
    idle_.notify_all();
  }

  // Wakes every waiter; pushes fail and take() returns nothing until stop_flushing(). Returns
  // what was waiting, in order, for the caller to release.
  std::vector<T> start_flushing() {
    std::vector<T> discarded;
    {
      const std::lock_guard lock(mutex_);
      flushing_ = true;
      for (auto& entry : entries_) discarded.push_back(std::move(entry.value));
      entries_.clear();
      frames_ = 0;
    }
    not_empty_.notify_all();
    not_full_.notify_all();
    idle_.notify_all();
    return discarded;
  }

  // Accepts items again, and forgets a failure.
  void stop_flushing() {
    const std::lock_guard lock(mutex_);
    flushing_ = false;
    failure_ = 0;
  }

  // The consumer could not pass an item on (`code` != 0, e.g. a GstFlowReturn): producers'
  // frame pushes fail with Result::failed from now on; failure() tells them the first code.
  void fail(int code) {
    {
      const std::lock_guard lock(mutex_);
      if (failure_ == 0) failure_ = code;
    }
    not_full_.notify_all();
    idle_.notify_all();
  }
  int failure() const {
    const std::lock_guard lock(mutex_);
    return failure_;
  }
  bool flushing() const {
    const std::lock_guard lock(mutex_);
    return flushing_;
  }

  // Waits until nothing waits and the consumer is idle; false when flushing or failed (the
  // consumer stopped taking: nothing is known about what was done).
  bool wait_drained() {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [&] { return flushing_ || failure_ != 0 || (entries_.empty() && !busy_); });
    return !flushing_ && failure_ == 0;
  }

  std::size_t frames_waiting() const {
    const std::lock_guard lock(mutex_);
    return frames_;
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable not_empty_;  // the consumer waits
  std::condition_variable not_full_;   // back-pressured producers wait
  std::condition_variable idle_;       // drains wait
  std::deque<Entry> entries_;
  std::size_t capacity_;
  std::size_t frames_ = 0;
  bool busy_ = false;
  bool flushing_ = false;
  int failure_ = 0;
};

}  // namespace neuflow::gst
