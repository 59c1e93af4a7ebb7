// probes/procedural.h: environments built in code, for tests and examples.
#pragma once

#include "probes/probe.h"

#include <functional>

namespace probes {

// Every texel holds `radiance`.
Probe make_constant(int width, int height, const Rgb& radiance);

// Texel = f(centre direction of the pixel). Rows are filled in parallel.
Probe make_from_function(int width, int height,
                         const std::function<Rgb(const Eigen::Vector3d&)>& radiance);

// Black, with a disc ("sun") of angular radius `radius_radians` about `direction` at
// radiance `radiance`; a pixel belongs to the disc when its centre does.
Probe make_sun(int width, int height, const Eigen::Vector3d& direction, double radius_radians,
               const Rgb& radiance);

}  // namespace probes
