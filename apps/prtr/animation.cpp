#include "animation.h"

#include "subprocess.h"

#include "common/output_path.h"

#include <OpenImageIO/imageio.h>

#include <unistd.h>

#include <cstdio>
#include <stdexcept>
#include <vector>

namespace prtr_app {
namespace fs = std::filesystem;
namespace {

std::string frame_png(int index) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%04d.png", index);
  return buf;
}

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

void write_gif(const fs::path& dir, int frames, int fps, const fs::path& output) {
  const TemporaryFile temporary{temporary_for(output)};
  auto fail = [&](const std::string& why) {
    throw std::runtime_error("cannot write the animation " + output.string() + ": " + why);
  };
  // By format name: the temporary's extension must not decide the format.
  auto gif = OIIO::ImageOutput::create("gif");
  if (!gif) fail("this OpenImageIO has no GIF writer");
  if (!gif->supports("multiimage")) fail("this OpenImageIO writes GIF without frames");
  std::vector<unsigned char> rgb;
  for (int f = 0; f < frames; ++f) {
    const fs::path path = dir / frame_png(f);
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) fail("cannot read frame " + path.string() + ": " + OIIO::geterror());
    const OIIO::ImageSpec& source = in->spec();
    OIIO::ImageSpec spec(source.width, source.height, 3, OIIO::TypeDesc::UINT8);
    const int rate[2] = {fps, 1};
    spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
    spec.attribute("oiio:LoopCount", 0);  // loop forever
    rgb.resize(std::size_t(spec.width) * std::size_t(spec.height) * 3);
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, rgb.data()))
      fail("cannot read frame " + path.string() + ": " + in->geterror());
    const auto mode = f == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendSubimage;
    if (!gif->open(temporary.path.string(), spec, mode)) fail(gif->geterror());
    if (!gif->write_image(OIIO::TypeDesc::UINT8, rgb.data())) fail(gif->geterror());
  }
  if (!gif->close()) fail(gif->geterror());
  commit(temporary.path, output);
}

VideoResult write_mp4(const fs::path& dir, int fps, const fs::path& output) {
  if (run_program({"ffmpeg", "-version"}, true) != 0) return VideoResult::kNoFfmpeg;
  const TemporaryFile temporary{temporary_for(output)};
  const int status =
      run_program({"ffmpeg", "-y", "-loglevel", "error", "-framerate", std::to_string(fps), "-i",
                   (dir / "frame_%04d.png").string(), "-vf", "scale=trunc(iw/2)*2:trunc(ih/2)*2",
                   "-pix_fmt", "yuv420p", "-f", "mp4", temporary.path.string()});
  if (status != 0) return VideoResult::kFailed;
  commit(temporary.path, output);
  return VideoResult::kWritten;
}

}  // namespace prtr_app
