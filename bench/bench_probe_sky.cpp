#include "bench_probe.h"

#include "probes/procedural.h"

#include <algorithm>
#include <cmath>

probes::Probe procedural_bench_probe() {
  // A blue-to-white sky, a dark ground and a small bright sun: directional enough that every
  // SH band of the lighting is non-zero, like a real probe.
  const Eigen::Vector3d sun = Eigen::Vector3d(0.4, 0.7, 0.6).normalized();
  return probes::make_from_function(1024, 512, [&](const Eigen::Vector3d& d) {
    const double up = std::max(0.0, d.y()), s = std::pow(std::max(0.0, d.dot(sun)), 64.0);
    return probes::Rgb(float(0.1 + 0.5 * up + 20.0 * s), float(0.1 + 0.6 * up + 18.0 * s),
                       float(0.08 + 0.9 * up + 15.0 * s));
  });
}
