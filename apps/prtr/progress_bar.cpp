#include "progress_bar.h"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace prtr_app {

ProgressBar::ProgressBar(bool quiet) : active_(!quiet && ::isatty(STDERR_FILENO)) {}

ProgressBar::~ProgressBar() {
  finish();
}

void ProgressBar::update(const std::string& label, std::uint64_t done, std::uint64_t total) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (label != label_) {
    if (drawn_) std::fputc('\n', stderr);
    label_ = label;
    start_ = now;
  }
  const double fraction = total ? double(done) / double(total) : 1.0;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  char eta[32] = "";
  if (fraction > 0.02 && fraction < 1.0) {
    std::snprintf(eta, sizeof eta, "ETA %.0fs", elapsed * (1.0 - fraction) / fraction);
  } else if (fraction >= 1.0) {
    std::snprintf(eta, sizeof eta, "%.1fs", elapsed);
  }
  constexpr int kWidth = 30;
  const int filled = int(fraction * kWidth + 0.5);
  std::string bar(std::size_t(filled), '#');
  bar.append(std::size_t(kWidth - filled), '.');
  std::fprintf(stderr, "\r%-22s [%s] %3d%%  %llu/%llu  %-12s", label.c_str(), bar.c_str(),
               int(fraction * 100 + 0.5), static_cast<unsigned long long>(done),
               static_cast<unsigned long long>(total), eta);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (active_ && drawn_) std::fputc('\n', stderr);
  drawn_ = false;
  label_.clear();
}

pipeline::Reporter stderr_reporter(bool quiet) {
  auto bar = std::make_shared<ProgressBar>(quiet);
  pipeline::Reporter r;
  r.progress = [bar](const std::string& phase, std::uint64_t done, std::uint64_t total) {
    bar->update(phase, done, total);
  };
  r.step_done = [bar] { bar->finish(); };
  if (!quiet) r.note = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  r.warning = [](const std::string& line) { std::fprintf(stderr, "prtr: %s\n", line.c_str()); };
  return r;
}

}  // namespace prtr_app
