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
// value is not finite. erode > 0 compares only pixels whose whole (2 erode + 1)^2 square is
// covered in both: silhouette pixels, which a sub-pixel difference in where the edge falls
// (or a view-dependent effect that lives only at grazing angles) changes completely, then
// drop out, and what remains measures the shading inside the outline.
ImageDifference image_difference(const Image& image, const Image& reference,
                                 float coverage = 0.999f, int erode = 0);

}  // namespace render
