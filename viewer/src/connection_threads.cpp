#include "connection_threads.h"

#include <dirent.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>

namespace viewer::detail {

ConnectionThreads::ConnectionThreads(std::size_t max_threads, std::chrono::milliseconds grace)
    : max_threads_(max_threads), grace_(grace) {}

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
    shut_down_tcp_connections();
    lock.lock();
  }
  std::vector<std::thread> threads = std::move(threads_);
  threads_.clear();
  lock.unlock();
  for (std::thread& t : threads) t.join();
}

void shut_down_tcp_connections() {
  DIR* fds = ::opendir("/proc/self/fd");
  if (fds == nullptr) return;
  while (const dirent* entry = ::readdir(fds)) {
    char* end = nullptr;
    const long fd = std::strtol(entry->d_name, &end, 10);
    if (end == entry->d_name || *end != '\0' || fd == ::dirfd(fds)) continue;
    struct stat st;
    if (::fstat(int(fd), &st) != 0 || !S_ISSOCK(st.st_mode)) continue;
    int type = 0, listening = 0;
    socklen_t size = sizeof type;
    if (::getsockopt(int(fd), SOL_SOCKET, SO_TYPE, &type, &size) != 0 || type != SOCK_STREAM)
      continue;
    size = sizeof listening;
    if (::getsockopt(int(fd), SOL_SOCKET, SO_ACCEPTCONN, &listening, &size) != 0 || listening)
      continue;
    sockaddr_storage address{};
    size = sizeof address;
    if (::getsockname(int(fd), reinterpret_cast<sockaddr*>(&address), &size) != 0 ||
        (address.ss_family != AF_INET && address.ss_family != AF_INET6))
      continue;
    ::shutdown(int(fd), SHUT_RDWR);
  }
  ::closedir(fds);
}

}  // namespace viewer::detail
