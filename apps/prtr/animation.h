// apps/prtr/animation.h: the animations `prtr relight` leaves beside its frame_NNNN.png
// previews: an animated GIF through OpenImageIO (always; Debian's OpenImageIO writes GIF
// with several subimages, but its WebP writer takes a single image) and an MP4 through
// ffmpeg when it is installed. Both appear under their names only when complete.
#pragma once

#include <filesystem>
#include <string>

namespace prtr_app {

// frame_0000.png .. frame_{frames-1}.png in `dir` -> `output`, looping forever at `fps`.
// Throws std::runtime_error naming the frame or the output when reading or writing fails.
void write_gif(const std::filesystem::path& dir, int frames, int fps,
               const std::filesystem::path& output);

enum class VideoResult { kWritten, kNoFfmpeg, kFailed };

// The same frames as H.264 in MP4 (yuv420p, so that every player opens it; odd sizes are
// rounded down to even, which yuv420p needs).
VideoResult write_mp4(const std::filesystem::path& dir, int fps,
                      const std::filesystem::path& output);

}  // namespace prtr_app
