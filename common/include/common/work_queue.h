// common/work_queue.h: tasks run on a few worker threads with a bounded backlog, so that a
// producer (a renderer handing over frames) overlaps its work with slow consumers (image
// writers) without holding more than `capacity` results in memory. The first task that
// throws stops the queue: later submissions and finish() rethrow its exception, so a disk
// error surfaces where the producer can report it.
#pragma once

#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace common {

class WorkQueue {
 public:
  // threads >= 1 workers; submit() blocks while `capacity` (>= 1) tasks wait to start.
  WorkQueue(int threads, int capacity);
  // Waits for the tasks already submitted; an exception they threw is dropped here (call
  // finish() to see it).
  ~WorkQueue();
  WorkQueue(const WorkQueue&) = delete;
  WorkQueue& operator=(const WorkQueue&) = delete;

  // Queues `task`; rethrows the exception of a task that failed earlier instead.
  void submit(std::function<void()> task);
  // Waits until every submitted task has run; rethrows the first exception one threw.
  void finish();

 private:
  void work();
  void rethrow_failure();  // with mutex_ held

  std::mutex mutex_;
  std::condition_variable task_ready_, space_free_, all_done_;
  std::deque<std::function<void()>> tasks_;
  std::vector<std::thread> workers_;
  std::exception_ptr failure_;
  std::size_t capacity_;
  int running_ = 0;
  bool stopping_ = false;
};

}  // namespace common
