// viewer/queue.h: the requests waiting for `prtr view`'s single render thread. At
// most one job per client waits: a newer request of a client whose job has not started yet
// replaces that job's state (the newest wins, by the client's `seq`) and shares its result,
// so dragging never builds a queue and every request is still answered, with the newest
// frame. Clients are served in the order their waiting job arrived, so one busy client
// cannot starve the others. Knows nothing of HTTP or GL (unit-tested alone).
#pragma once

#include "viewer/request.h"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>

namespace viewer {

struct RenderedFrame;  // viewer/frame.h
using FramePtr = std::shared_ptr<const RenderedFrame>;

// The queue refuses work: too many clients waiting at once, or the server is stopping.
class QueueRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FrameQueue {
 public:
  using Clock = std::chrono::steady_clock;

  struct Job {
    ViewState state;
    std::promise<FramePtr> promise;
    Clock::time_point submitted;  // of the first request the job answers
    int requests = 1;             // requests answered by this job (1 + coalesced)
  };
  struct Counters {
    std::uint64_t requests = 0, coalesced = 0, jobs_taken = 0;
  };

  explicit FrameQueue(std::size_t max_waiting_clients = 64);

  // The result this request will get. Throws QueueRefused when `max_waiting_clients` other
  // clients already wait or after stop().
  std::shared_future<FramePtr> submit(const ViewState& state);

  // The next job, oldest waiting client first; blocks; nullopt once stopped.
  std::optional<Job> take();

  // Wakes take() for good and fails every waiting job with QueueRefused.
  void stop();

  Counters counters() const;
  std::size_t waiting() const;

 private:
  struct Waiting {
    Job job;
    std::shared_future<FramePtr> result;
  };
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  std::map<std::string, Waiting> waiting_;  // by client
  std::deque<std::string> order_;           // clients, by arrival of their waiting job
  std::size_t max_waiting_;
  bool stopped_ = false;
  Counters counters_;
};

}  // namespace viewer
