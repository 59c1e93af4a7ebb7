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
  // With a second reference (the same image traced again with other random numbers), the
  // references' own noise taken out: for independent noise of the same variance in both,
  // mean (a - r)^2 exceeds the squared error against the exact image by that variance, and
  // mean (r - r2)^2 is twice it. -1 without a second reference.
  double reference_noise = -1.0;  // sqrt(mean (r - r2)^2 / 2) / sqrt(mean r^2): one reference's
  double corrected_relative_rmse = -1.0;  // sqrt(max(0, mean (a - r)^2 - mean (r - r2)^2 / 2))
                                          // / sqrt(mean r^2): against the exact image
};

// Throws std::invalid_argument when the sizes differ, nothing is compared or a compared
// value is not finite. erode > 0 compares only pixels whose whole (2 erode + 1)^2 square is
// covered in both: silhouette pixels, which a sub-pixel difference in where the edge falls
// (or a view-dependent effect that lives only at grazing angles) changes completely, then
// drop out, and what remains measures the shading inside the outline. A second reference
// (same size; null: none) restricts the pixels to those covered in all three and fills in
// reference_noise and corrected_relative_rmse.
ImageDifference image_difference(const Image& image, const Image& reference,
                                 float coverage = 0.999f, int erode = 0,
                                 const Image* second_reference = nullptr);

}  // namespace render
