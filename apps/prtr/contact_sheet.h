// apps/prtr/contact_sheet.h: thumbnails of a frame sequence tiled into one image (linear
// radiance, tone-mapped only when written as PNG).
#pragma once

#include "render/image.h"

#include <vector>

namespace prtr_app {

// Box-filtered reduction to `width` pixels wide (height keeps the aspect ratio, at least 1).
render::Image downscale(const render::Image& image, int width);

// Tiles same-sized thumbnails row by row, `columns` per row, `gap` pixels apart (alpha 0 in
// the gaps and the unused cells).
render::Image tile(const std::vector<render::Image>& thumbnails, int columns, int gap = 4);

}  // namespace prtr_app
