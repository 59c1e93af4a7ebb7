#include "animation.h"

#include "subprocess.h"

#include "common/output_path.h"

#include <unistd.h>

#include <stdexcept>

namespace prtr_app {
namespace fs = std::filesystem;
namespace {

// Beside the target so the rename stays within one file system; hidden, and named by this
// process so two runs into one directory do not collide.
fs::path temporary_for(const fs::path& target) {
  // Appended piece by piece: GCC 12 misreads "." + std::string as an overlapping memcpy
  // (-Wrestrict false positive).
  std::string name(".");
  name += target.stem().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += target.extension().string();
  return target.parent_path() / name;
}

// Removes the temporary file unless the rename happened.
struct TemporaryFile {
  fs::path path;
  ~TemporaryFile() {
    std::error_code ec;
    fs::remove(path, ec);
  }
};

void commit(const fs::path& temporary, const fs::path& target) {
  common::check_output_target(target);
  std::error_code ec;
  fs::rename(temporary, target, ec);
  if (ec) throw std::runtime_error("cannot write " + target.string() + ": " + ec.message());
}

}  // namespace

VideoResult write_mp4(const fs::path& dir, int fps, const fs::path& output) {
  if (run_program({"ffmpeg", "-version"}, true) != 0) return VideoResult::kNoFfmpeg;
  const TemporaryFile temporary{temporary_for(output)};
  const int status = run_program({"ffmpeg", "-y", "-loglevel", "error", "-framerate",
                                  std::to_string(fps), "-i", (dir / "frame_%04d.png").string(),
                                  "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2", "-pix_fmt", "yuv420p",
                                  "-preset", "veryfast", "-f", "mp4", temporary.path.string()});
  if (status != 0) return VideoResult::kFailed;
  commit(temporary.path, output);
  return VideoResult::kWritten;
}

}  // namespace prtr_app
