#include "render/supersample.h"

#include <stdexcept>
#include <string>

namespace render {

Camera supersampled(const Camera& camera, int factor) {
  if (factor < 1) throw std::invalid_argument("--supersample must be >= 1");
  Camera c = camera;
  c.width *= factor;
  c.height *= factor;
  return c;
}

Image box_downsample(const Image& image, int factor) {
  if (factor < 1 || image.width % factor != 0 || image.height % factor != 0)
    throw std::invalid_argument("box_downsample: " + std::to_string(image.width) + " x " +
                                std::to_string(image.height) + " is not a multiple of " +
                                std::to_string(factor));
  Image out;
  out.width = image.width / factor;
  out.height = image.height / factor;
  out.rgba.assign(std::size_t(out.width) * out.height * 4, 0.f);
  const float weight = 1.f / float(factor * factor);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      float* dst = out.pixel(x, y);
      for (int dy = 0; dy < factor; ++dy)
        for (int dx = 0; dx < factor; ++dx) {
          const float* src = image.pixel(x * factor + dx, y * factor + dy);
          for (int c = 0; c < 4; ++c) dst[c] += src[c] * weight;
        }
    }
  return out;
}

}  // namespace render
