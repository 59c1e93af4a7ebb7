// viewer/compressions.h: the compressions the page can switch between, as PRTDemo let a user
// change clusters and PCs while it ran. The launch's is ready at once; another (clusters,
// PCs) is made in the background by the function the app supplies (the cached pipeline, so
// a second request is a cache hit), one at a time, while frames keep showing the last one
// that was ready.
#pragma once

#include "cpca/compressed.h"

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace viewer {

// Makes the compression with `clusters` clusters and `pcs` PCs; reports its progress in
// [0, 1] through `progress`; throws on failure (the message is shown to the page).
using MakeCompression = std::function<cpca::CompressedSet(
    int clusters, int pcs, const std::function<void(double)>& progress)>;

struct CompressionStatus {
  std::shared_ptr<const cpca::CompressedSet> shown;  // what to render now
  bool pending = false;   // the asked-for compression is being made (or waits its turn)
  double progress = 0.0;  // of the one being made, in [0, 1]
  std::string error;      // why the asked-for compression could not be made
};

class Compressions {
 public:
  // `make` empty: only the launch's compression is offered.
  Compressions(cpca::CompressedSet launch, MakeCompression make);
  ~Compressions();  // waits for a compression in progress
  Compressions(const Compressions&) = delete;
  Compressions& operator=(const Compressions&) = delete;

  const cpca::CompressedSet& launch() const { return *launch_; }

  // The compression to show for a request of (clusters, pcs), 0 meaning the launch's value.
  // A ready one becomes the one shown; one not made yet is started (or queued behind the one
  // in progress, replacing any earlier queued request), and the last ready one is shown.
  CompressionStatus choose(int clusters, int pcs);

 private:
  using Key = std::pair<int, int>;
  void work();  // the worker thread: makes queued compressions until none is left

  static constexpr std::size_t kKept = 4;  // made compressions kept besides the launch's

  const std::shared_ptr<const cpca::CompressedSet> launch_;
  const MakeCompression make_;
  std::mutex mutex_;
  std::map<Key, std::shared_ptr<const cpca::CompressedSet>> made_;
  std::map<Key, std::string> failed_;
  std::shared_ptr<const cpca::CompressedSet> shown_;
  std::optional<Key> making_, queued_;
  double progress_ = 0.0;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace viewer
