// viewer/compressions.h: the compressions the page can switch between, as PRTDemo let a user
// change clusters, PCs and SH order while it ran. The launch's is ready at once; another
// (clusters, PCs, order) is made in the background by the function the app supplies (the
// cached pipeline: another order bakes first, and a second request is a cache hit), one at a
// time, while frames keep showing the last one that was ready.
#pragma once

#include "cpca/compressed.h"

#include <compare>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace viewer {

// A compression and the bake it was made from (the uncompressed mode and the difference view
// render that bake, at the compression's order).
struct Compression {
  cpca::CompressedSet set;
  std::filesystem::path transfer;
};

// Makes the compression with `clusters` clusters and `pcs` PCs at SH order `order`; reports
// its progress in [0, 1] through `progress`; throws on failure (the message is shown to the
// page).
using MakeCompression = std::function<Compression(int clusters, int pcs, int order,
                                                  const std::function<void(double)>& progress)>;

struct CompressionStatus {
  std::shared_ptr<const cpca::CompressedSet> shown;  // what to render now
  std::filesystem::path transfer;                    // the bake `shown` was made from
  bool pending = false;   // the asked-for compression is being made (or waits its turn)
  double progress = 0.0;  // of the one being made, in [0, 1]
  std::string error;      // why the asked-for compression could not be made
};

class Compressions {
 public:
  // `make` empty: only the launch's compression is offered.
  Compressions(Compression launch, MakeCompression make);
  ~Compressions();  // waits for a compression in progress
  Compressions(const Compressions&) = delete;
  Compressions& operator=(const Compressions&) = delete;

  const cpca::CompressedSet& launch() const { return launch_->set; }

  // The compression to show for a request of (clusters, pcs, order), 0 meaning the launch's
  // value. A ready one becomes the one shown; one not made yet is started (or queued behind
  // the one in progress, replacing any earlier queued request), and the last ready one is
  // shown.
  CompressionStatus choose(int clusters, int pcs, int order = 0);

 private:
  struct Key {
    int clusters = 0, pcs = 0, order = 0;
    auto operator<=>(const Key&) const = default;
  };
  // The set aliases its Compression, which keeps the bake's path beside it.
  using Made = std::shared_ptr<const Compression>;
  CompressionStatus status(bool pending, double progress, std::string error) const;
  void work();  // the worker thread: makes queued compressions until none is left

  static constexpr std::size_t kKept = 4;  // made compressions kept besides the launch's

  const Made launch_;
  const MakeCompression make_;
  std::mutex mutex_;
  std::map<Key, Made> made_;
  std::map<Key, std::string> failed_;
  Made shown_;
  std::optional<Key> making_, queued_;
  double progress_ = 0.0;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace viewer
