// pipeline/reporter.h: how the pipeline's long steps tell their caller what they do, so that
// the library never writes to a terminal itself: the command draws a progress bar and prints
// the lines, a test or a server passes nothing. Every member may be empty (that news is
// dropped).
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace pipeline {

struct Reporter {
  // A step's progress: its phase name, units done and total. ETA-style displays restart when
  // the phase name changes.
  std::function<void(const std::string& phase, std::uint64_t done, std::uint64_t total)> progress;
  // The step whose progress was reported has ended (a bar ends its line).
  std::function<void()> step_done;
  // What a step is about to do and roughly what it costs (one line, no newline).
  std::function<void(const std::string& line)> note;
  // Something the user should know even when not watching progress: a cache entry that was
  // unusable and rebuilt, temporaries of an interrupted run removed (one line, no newline).
  std::function<void(const std::string& line)> warning;

  void report(const std::string& phase, std::uint64_t done, std::uint64_t total) const {
    if (progress) progress(phase, done, total);
  }
  void end_step() const {
    if (step_done) step_done();
  }
  void tell(const std::string& line) const {
    if (note) note(line);
  }
  void warn(const std::string& line) const {
    if (warning) warning(line);
  }
};

}  // namespace pipeline
