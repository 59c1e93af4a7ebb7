// viewer/src/connection_threads.h (private): the task queue prtr view gives cpp-httplib, a
// thread for every open connection up to a cap.
//
// httplib serves a connection on one thread for its whole life (keep-alive included) and
// bounds each read, not a request's headers as a whole, so a client that sends one header
// line a second holds its thread for minutes. With httplib's fixed pool of 16, 16 such
// clients locked every other client out, and SIGTERM waited for them. Here every connection
// gets a thread while fewer than the cap are open (past it, new connections wait for one), so
// slow clients hold only their own threads. When the server stops, open connections get a
// short grace period to finish their answer; then their sockets are shut down, which ends
// the blocked reads, and the threads are joined.
#pragma once

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace viewer::detail {

class ConnectionThreads : public httplib::TaskQueue {
 public:
  ConnectionThreads(std::size_t max_threads, std::chrono::milliseconds grace);
  ~ConnectionThreads() override;

  void enqueue(std::function<void()> connection) override;
  void shutdown() override;

 private:
  void work();

  const std::size_t max_threads_;
  const std::chrono::milliseconds grace_;
  std::mutex mutex_;
  std::condition_variable wake_;  // a connection waits, or stopping
  std::condition_variable idle_;  // a connection ended
  std::deque<std::function<void()>> waiting_;
  std::vector<std::thread> threads_;
  std::size_t idle_threads_ = 0;
  std::size_t busy_ = 0;
  bool stopping_ = false;
};

// Shuts down (both directions) every connected TCP socket of this process, so that threads
// blocked reading from them return. prtr view has no other TCP connections.
void shut_down_tcp_connections();

}  // namespace viewer::detail
