// apps/prtr/progress_bar.h: a one-line progress bar with ETA on stderr. It draws only when
// stderr is a terminal and --quiet was not given; otherwise every call is a no-op, so logs
// and CI output stay clean.
#pragma once

#include "common/format_bytes.h"
#include "pipeline/reporter.h"

#include <chrono>
#include <cstdint>
#include <string>

namespace prtr_app {

class ProgressBar {
 public:
  explicit ProgressBar(bool quiet);
  ~ProgressBar();
  // `label` names the phase; ETA restarts when the label changes.
  void update(const std::string& label, std::uint64_t done, std::uint64_t total);
  // Ends the line (if one is drawn).
  void finish();
  bool active() const { return active_; }

 private:
  bool active_;
  bool drawn_ = false;
  std::string label_;
  std::chrono::steady_clock::time_point start_;
};

// The pipeline's news on stderr: a progress bar and notes unless `quiet`, warnings always
// (prefixed "prtr: ").
pipeline::Reporter stderr_reporter(bool quiet);

using common::format_bytes;

}  // namespace prtr_app
