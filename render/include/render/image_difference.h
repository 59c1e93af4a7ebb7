// render/image_difference.h: how far an image is from a reference (a path-traced one, prtr
// path-trace), over the pixels the mesh covers in both, so the background does not dilute it.
#pragma once

#include "render/image.h"

#include <cstdint>

namespace render {

struct ImageDifference {
  std::uint64_t pixels = 0;    // compared: alpha >= coverage in both (or all, coverage 0)
  double rmse = 0.0;           // sqrt(mean over pixels and RGB of (a - r)^2)
  double relative_rmse = 0.0;  // rmse / sqrt(mean of r^2): the issue tables' "relative RMSE"
  double mean_abs = 0.0;       // mean |a - r|
  double max_abs = 0.0;        // largest |a - r|
};

// Throws std::invalid_argument when the sizes differ, nothing is compared or a compared
// value is not finite.
ImageDifference image_difference(const Image& image, const Image& reference,
                                 float coverage = 0.999f);

}  // namespace render
