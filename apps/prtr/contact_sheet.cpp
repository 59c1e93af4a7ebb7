#include "contact_sheet.h"

#include <algorithm>
#include <stdexcept>

namespace prtr_app {

render::Image downscale(const render::Image& image, int width) {
  if (width < 1 || image.width < 1 || image.height < 1)
    throw std::invalid_argument("downscale: empty image or width");
  width = std::min(width, image.width);
  const int height = std::max(1, int(double(image.height) * width / image.width + 0.5));
  render::Image out;
  out.width = width;
  out.height = height;
  out.rgba.assign(std::size_t(width) * height * 4, 0.f);
  for (int y = 0; y < height; ++y) {
    const int y0 = y * image.height / height,
              y1 = std::max(y0 + 1, (y + 1) * image.height / height);
    for (int x = 0; x < width; ++x) {
      const int x0 = x * image.width / width, x1 = std::max(x0 + 1, (x + 1) * image.width / width);
      float* o = out.pixel(x, y);
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx)
          for (int c = 0; c < 4; ++c) o[c] += image.pixel(sx, sy)[c];
      const float inv = 1.f / float((y1 - y0) * (x1 - x0));
      for (int c = 0; c < 4; ++c) o[c] *= inv;
    }
  }
  return out;
}

render::Image tile(const std::vector<render::Image>& thumbnails, int columns, int gap) {
  if (thumbnails.empty() || columns < 1) throw std::invalid_argument("tile: nothing to tile");
  const int w = thumbnails[0].width, h = thumbnails[0].height;
  const int n = int(thumbnails.size()), cols = std::min(columns, n), rows = (n + cols - 1) / cols;
  render::Image sheet;
  sheet.width = cols * w + (cols + 1) * gap;
  sheet.height = rows * h + (rows + 1) * gap;
  sheet.rgba.assign(std::size_t(sheet.width) * sheet.height * 4, 0.f);
  for (int i = 0; i < n; ++i) {
    const render::Image& t = thumbnails[std::size_t(i)];
    if (t.width != w || t.height != h)
      throw std::invalid_argument("tile: thumbnails differ in size");
    const int ox = gap + (i % cols) * (w + gap), oy = gap + (i / cols) * (h + gap);
    for (int y = 0; y < h; ++y)
      std::copy(t.pixel(0, y), t.pixel(0, y) + std::size_t(w) * 4, sheet.pixel(ox, oy + y));
  }
  return sheet;
}

}  // namespace prtr_app
