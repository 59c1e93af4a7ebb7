#include "prt/projection.h"

#include "prt/cube_projection.h"

#include "prt/sh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace prt {

ShLighting project(const probes::Probe& probe, int order) {
  if (probe.source_cube()) return project_cube(*probe.source_cube(), order);
  return project_latlong(probe, order);
}

ShLighting project_latlong(const probes::Probe& probe, int order) {
  check_order(order, "projection order");
  if (probe.width() <= 0 || probe.height() <= 0) {
    throw std::invalid_argument("project: probe '" + probe.name() + "' is empty");
  }
  const int n = sh_count(order);
  const int width = probe.width();
  const int height = probe.height();
  std::vector<ShLighting> rows(height, ShLighting::Zero(n, 3));

  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
    // Per-task buffers: one SH matrix and one weighted radiance block per row.
    Eigen::Matrix3Xd directions(3, width);
    ShBatchD basis(n, width);
    Eigen::Matrix<double, Eigen::Dynamic, 3> weighted(width, 3);
    for (int y = r.begin(); y != r.end(); ++y) {
      const double solid_angle = probe.pixel_solid_angle(y);
      for (int x = 0; x < width; ++x) {
        directions.col(x) = probe.pixel_direction(x, y);
        weighted.row(x) = probe.texel(x, y).cast<double>().transpose() * solid_angle;
      }
      sh_eval_batch(order, directions, basis);
      rows[y].noalias() = basis * weighted;
    }
  });

  ShLighting total = ShLighting::Zero(n, 3);
  for (const ShLighting& row : rows) total += row;
  return total;
}

probes::Probe reconstruct(const Eigen::Ref<const ShLighting>& lighting, int width, int height) {
  const int order = sh_band(static_cast<int>(lighting.rows()) - 1) + 1;
  if (sh_count(order) != lighting.rows()) {
    throw std::invalid_argument("reconstruct: " + std::to_string(lighting.rows()) +
                                " rows is not an SH coefficient count");
  }
  check_order(order, "reconstruction order");
  if (width != 2 * height || height <= 0) {
    throw std::invalid_argument("reconstruct: size must be 2h x h, got " + std::to_string(width) +
                                "x" + std::to_string(height));
  }
  const int n = sh_count(order);
  std::vector<probes::Rgb> texels(std::size_t(width) * height);
  tbb::parallel_for(0, height, [&](int y) {
    double basis[kMaxOrder * kMaxOrder];
    for (int x = 0; x < width; ++x) {
      sh_eval(order, probes::latlong_direction((x + 0.5) / width, (y + 0.5) / height), basis);
      Eigen::Vector3d value = Eigen::Map<const Eigen::VectorXd>(basis, n).transpose() * lighting;
      texels[std::size_t(y) * width + x] = value.cast<float>();
    }
  });
  return probes::Probe(width, height, std::move(texels), "sh-reconstruction");
}

}  // namespace prt
