#include "common/work_queue.h"

#include <stdexcept>
#include <string>

namespace common {

WorkQueue::WorkQueue(int threads, int capacity) {
  if (threads < 1 || capacity < 1)
    throw std::invalid_argument("a work queue needs at least one thread and one slot, not " +
                                std::to_string(threads) + " and " + std::to_string(capacity));
  capacity_ = std::size_t(capacity);
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

WorkQueue::~WorkQueue() {
  {
    std::unique_lock lock(mutex_);
    all_done_.wait(lock, [this] { return tasks_.empty() && running_ == 0; });
    stopping_ = true;
  }
  task_ready_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void WorkQueue::rethrow_failure() {
  if (failure_) std::rethrow_exception(failure_);
}

void WorkQueue::submit(std::function<void()> task) {
  std::unique_lock lock(mutex_);
  space_free_.wait(lock, [this] { return tasks_.size() < capacity_ || failure_; });
  rethrow_failure();
  tasks_.push_back(std::move(task));
  task_ready_.notify_one();
}

void WorkQueue::finish() {
  std::unique_lock lock(mutex_);
  all_done_.wait(lock, [this] { return tasks_.empty() && running_ == 0; });
  rethrow_failure();
}

void WorkQueue::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    task_ready_.wait(lock, [this] { return stopping_ || !tasks_.empty(); });
    if (tasks_.empty()) return;  // stopping, nothing left
    std::function<void()> task = std::move(tasks_.front());
    tasks_.pop_front();
    ++running_;
    space_free_.notify_one();
    lock.unlock();
    std::exception_ptr error;
    try {
      task();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    --running_;
    if (error && !failure_) {
      failure_ = error;
      tasks_.clear();  // nothing after a failure is worth writing
      space_free_.notify_all();
    }
    if (tasks_.empty() && running_ == 0) all_done_.notify_all();
  }
}

}  // namespace common
