#include "viewer/compressions.h"

#include <exception>

namespace viewer {

Compressions::Compressions(cpca::CompressedSet launch, MakeCompression make)
    : launch_(std::make_shared<const cpca::CompressedSet>(std::move(launch))),
      make_(std::move(make)),
      shown_(launch_) {
  made_[{launch_->cluster_count, launch_->component_count}] = launch_;
}

Compressions::~Compressions() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    queued_.reset();
  }
  if (worker_.joinable()) worker_.join();
}

CompressionStatus Compressions::choose(int clusters, int pcs) {
  const Key key{clusters > 0 ? clusters : launch_->cluster_count,
                pcs > 0 ? pcs : launch_->component_count};
  std::lock_guard lock(mutex_);
  if (const auto it = made_.find(key); it != made_.end()) {
    shown_ = it->second;
    return {shown_, false, 1.0, {}};
  }
  if (const auto it = failed_.find(key); it != failed_.end())
    return {shown_, false, 0.0, it->second};
  if (!make_) return {shown_, false, 0.0, "this viewer offers only its launch compression"};
  if (making_ == key) return {shown_, true, progress_, {}};
  queued_ = key;
  if (!making_) {
    // The previous worker has set making_ empty as its last act under the lock.
    if (worker_.joinable()) worker_.join();
    making_ = queued_;
    queued_.reset();
    progress_ = 0.0;
    worker_ = std::thread([this] { work(); });
  }
  return {shown_, true, making_ == key ? progress_ : 0.0, {}};
}

void Compressions::work() {
  std::unique_lock lock(mutex_);
  while (making_ && !stopping_) {
    const Key key = *making_;
    lock.unlock();
    std::shared_ptr<const cpca::CompressedSet> set;
    std::string error;
    try {
      set = std::make_shared<const cpca::CompressedSet>(
          make_(key.first, key.second, [this](double done) {
            std::lock_guard progress_lock(mutex_);
            progress_ = done;
          }));
    } catch (const std::exception& e) {
      error = e.what();
    }
    lock.lock();
    if (set) {
      // Keep the launch's, the shown one and the newest; drop the others, oldest key first.
      while (made_.size() > kKept) {
        auto victim = made_.begin();
        while (victim != made_.end() && (victim->second == launch_ || victim->second == shown_))
          ++victim;
        if (victim == made_.end()) break;
        made_.erase(victim);
      }
      made_[key] = std::move(set);
    } else {
      failed_[key] = error;
    }
    making_ = queued_;
    queued_.reset();
    progress_ = 0.0;
  }
  making_.reset();
}

}  // namespace viewer
