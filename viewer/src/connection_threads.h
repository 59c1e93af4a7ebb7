// viewer/src/connection_threads.h (private): the threads of prtr view's HTTP server
// (viewer/src/http_server.h), one for every open connection up to a cap.
//
// A connection is served on one thread for its whole life (keep-alive included), so with a
// fixed pool of 16 (cpp-httplib's, before), 16 clients sending one header line a second
// locked every other client out, and SIGTERM waited for them. Here every connection gets a
// thread while fewer than the cap are open (past it, new connections wait for one), so slow
// clients hold only their own threads. When the server stops, open connections get a short
// grace period to finish their answer; then `cut_off` runs (the server shuts their sockets
// down, which ends blocked reads and writes) and the threads are joined.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace viewer::detail {

class ConnectionThreads {
 public:
  ConnectionThreads(std::size_t max_threads, std::chrono::milliseconds grace,
                    std::function<void()> cut_off);
  ~ConnectionThreads();
  ConnectionThreads(const ConnectionThreads&) = delete;
  ConnectionThreads& operator=(const ConnectionThreads&) = delete;

  void enqueue(std::function<void()> connection);
  // Serves what is waiting, waits up to the grace period, cuts off, joins. Idempotent.
  void shutdown();

 private:
  void work();

  const std::size_t max_threads_;
  const std::chrono::milliseconds grace_;
  const std::function<void()> cut_off_;
  std::mutex mutex_;
  std::condition_variable wake_;  // a connection waits, or stopping
  std::condition_variable idle_;  // a connection ended
  std::deque<std::function<void()>> waiting_;
  std::vector<std::thread> threads_;
  std::size_t idle_threads_ = 0;
  std::size_t busy_ = 0;
  bool stopping_ = false;
};

}  // namespace viewer::detail
