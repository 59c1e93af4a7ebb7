// probes/src/rgbe_file.h: Radiance RGBE (.hdr) files read by our own bounded reader (Ward,
// "Real Pixels", Graphics Gems II, 1991; the run-length scheme of Radiance 2.0), not by the
// image module (common/image_codec.h): the format is small and fully specified, light probes
// are commonly shipped in it, and a machine without OpenImageIO's libraries (a GPU host given
// a bundle) can then still load a probe.
//
// Accepted: FORMAT=32-bit_rle_rgbe (or no FORMAT line), a "-Y H +X W" or "+Y H +X W"
// resolution, scanlines flat, in the old run-length scheme (1, 1, 1, n repeats the previous
// pixel) or the new one (2, 2, W, per-channel runs). Refused, naming the cause: XYZE pixels,
// transposed or mirrored resolutions, and any scanline that is cut short, overruns its width
// or repeats before its first pixel. Pixels decode as mantissa x 2^(exponent - 136), as
// Radiance's reference code and OpenImageIO do; EXPOSURE is reported, not applied (neither
// applies it).
#pragma once

#include "common/image_codec.h"

#include <filesystem>
#include <memory>
#include <string>

namespace probes::detail {

// Whether the file starts with "#?RADIANCE" or "#?RGBE" (then open_rgbe reads it).
bool is_rgbe(const std::filesystem::path& path);

// The file opened (its header parsed, the pixels not yet read); null with *error set when the
// header is malformed. read() fails with *error set on a damaged scanline.
std::unique_ptr<common::ImageFile> open_rgbe(const std::filesystem::path& path, std::string* error);

}  // namespace probes::detail
