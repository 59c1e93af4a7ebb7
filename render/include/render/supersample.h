// render/supersample.h: anti-aliasing for offline output by supersampling. The frame is
// rendered `factor` times larger in each direction (the same view) and box-filtered back:
// exact coverage averaging for edges and the background, no MSAA resolve of the RGBA32F
// target needed, and linear radiance stays linear (EXR).
#pragma once

#include "render/camera.h"
#include "render/image.h"

namespace render {

// The same view at `factor` times the resolution (factor >= 1).
Camera supersampled(const Camera& camera, int factor);

// Each output pixel the mean of a factor x factor block (RGB and alpha = coverage); the
// image's size must be a multiple of factor.
Image box_downsample(const Image& image, int factor);

}  // namespace render
