#include "connection_threads.h"

namespace viewer::detail {

ConnectionThreads::ConnectionThreads(std::size_t max_threads, std::chrono::milliseconds grace,
                                     std::function<void()> cut_off)
    : max_threads_(max_threads), grace_(grace), cut_off_(std::move(cut_off)) {}

ConnectionThreads::~ConnectionThreads() {
  shutdown();
}

void ConnectionThreads::enqueue(std::function<void()> connection) {
  std::lock_guard<std::mutex> lock(mutex_);
  waiting_.push_back(std::move(connection));
  if (idle_threads_ < waiting_.size() && threads_.size() < max_threads_)
    threads_.emplace_back([this] { work(); });
  wake_.notify_one();
}

void ConnectionThreads::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    ++idle_threads_;
    wake_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
    --idle_threads_;
    if (waiting_.empty()) return;  // stopping, nothing left to serve
    std::function<void()> connection = std::move(waiting_.front());
    waiting_.pop_front();
    ++busy_;
    lock.unlock();
    connection();
    lock.lock();
    --busy_;
    idle_.notify_all();
  }
}

void ConnectionThreads::shutdown() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (stopping_ && threads_.empty()) return;
  stopping_ = true;
  wake_.notify_all();
  // Answers in progress may finish; connections that only hold a socket open may not.
  if (!idle_.wait_for(lock, grace_, [this] { return busy_ == 0 && waiting_.empty(); })) {
    lock.unlock();
    cut_off_();
    lock.lock();
  }
  std::vector<std::thread> threads = std::move(threads_);
  threads_.clear();
  lock.unlock();
  for (std::thread& t : threads) t.join();
}

}  // namespace viewer::detail
