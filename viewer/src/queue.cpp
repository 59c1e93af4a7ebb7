#include "viewer/queue.h"

#include <exception>

namespace viewer {

FrameQueue::FrameQueue(std::size_t max_waiting_clients) : max_waiting_(max_waiting_clients) {}

std::shared_future<FramePtr> FrameQueue::submit(const ViewState& state) {
  std::lock_guard lock(mutex_);
  if (stopped_) throw QueueRefused("the server is stopping");
  ++counters_.requests;
  const auto it = waiting_.find(state.client);
  if (it != waiting_.end()) {
    // Requests of one client can overtake each other on separate connections: the larger
    // seq is the newer view, whichever arrived last.
    Job& job = it->second.job;
    if (state.seq >= job.state.seq) job.state = state;
    ++job.requests;
    ++counters_.coalesced;
    return it->second.result;
  }
  if (waiting_.size() >= max_waiting_)
    throw QueueRefused("too many clients waiting (" + std::to_string(max_waiting_) + ")");
  Waiting w;
  w.job.state = state;
  w.job.submitted = Clock::now();
  w.result = w.job.promise.get_future().share();
  std::shared_future<FramePtr> result = w.result;
  waiting_.emplace(state.client, std::move(w));
  order_.push_back(state.client);
  ready_.notify_one();
  return result;
}

std::optional<FrameQueue::Job> FrameQueue::take() {
  std::unique_lock lock(mutex_);
  ready_.wait(lock, [&] { return stopped_ || !order_.empty(); });
  if (stopped_) return std::nullopt;
  const std::string client = order_.front();
  order_.pop_front();
  auto node = waiting_.extract(client);
  ++counters_.jobs_taken;
  return std::move(node.mapped().job);
}

void FrameQueue::stop() {
  std::lock_guard lock(mutex_);
  stopped_ = true;
  for (auto& [client, w] : waiting_)
    w.job.promise.set_exception(std::make_exception_ptr(QueueRefused("the server is stopping")));
  waiting_.clear();
  order_.clear();
  ready_.notify_all();
}

FrameQueue::Counters FrameQueue::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::size_t FrameQueue::waiting() const {
  std::lock_guard lock(mutex_);
  return waiting_.size();
}

}  // namespace viewer
