// apps/prtr/animation.h: the MP4 `prtr relight` encodes from its frame_NNNN.png previews
// through ffmpeg when it is installed (the GIF comes from render/gif.h). It appears under its
// name only when complete.
#pragma once

#include <filesystem>
#include <string>

namespace prtr_app {

enum class VideoResult { kWritten, kNoFfmpeg, kFailed };

// frame_0000.png onwards in `dir` as H.264 in MP4 (yuv420p, so that every player opens it; odd
// sizes are rounded down to even, which yuv420p needs).
VideoResult write_mp4(const std::filesystem::path& dir, int fps,
                      const std::filesystem::path& output);

}  // namespace prtr_app
