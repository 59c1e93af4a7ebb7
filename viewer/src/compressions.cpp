#include "viewer/compressions.h"

#include <exception>

namespace viewer {

Compressions::Compressions(Compression launch, MakeCompression make)
    : launch_(std::make_shared<const Compression>(std::move(launch))),
      make_(std::move(make)),
      shown_(launch_) {
  made_[{launch_->set.cluster_count, launch_->set.component_count, launch_->set.order}] = launch_;
}

CompressionStatus Compressions::status(bool pending, double progress, std::string error) const {
  return {std::shared_ptr<const cpca::CompressedSet>(shown_, &shown_->set), shown_->transfer,
          pending, progress, std::move(error)};
}

Compressions::~Compressions() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    queued_.reset();
  }
  if (worker_.joinable()) worker_.join();
}

CompressionStatus Compressions::choose(int clusters, int pcs, int order) {
  const cpca::CompressedSet& l = launch_->set;
  const Key key{clusters > 0 ? clusters : l.cluster_count, pcs > 0 ? pcs : l.component_count,
                order > 0 ? order : l.order};
  std::lock_guard lock(mutex_);
  if (const auto it = made_.find(key); it != made_.end()) {
    shown_ = it->second;
    return status(false, 1.0, {});
  }
  if (const auto it = failed_.find(key); it != failed_.end()) return status(false, 0.0, it->second);
  if (!make_) return status(false, 0.0, "this viewer offers only its launch compression");
  if (making_ == key) return status(true, progress_, {});
  queued_ = key;
  if (!making_) {
    // The previous worker has set making_ empty as its last act under the lock.
    if (worker_.joinable()) worker_.join();
    making_ = queued_;
    queued_.reset();
    progress_ = 0.0;
    worker_ = std::thread([this] { work(); });
  }
  return status(true, making_ == key ? progress_ : 0.0, {});
}

void Compressions::work() {
  std::unique_lock lock(mutex_);
  while (making_ && !stopping_) {
    const Key key = *making_;
    lock.unlock();
    Made set;
    std::string error;
    try {
      set = std::make_shared<const Compression>(
          make_(key.clusters, key.pcs, key.order, [this](double done) {
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
