// prt/projection.h: projecting environment maps onto SH, and back.
//
// Lighting is an n x 3 matrix (rows = SH coefficients in the order of prt/sh.h, columns =
// linear R, G, B in the probe's units), in the world frame. Projection is the quadrature
//     l_i = sum over pixels L(pixel) y_i(centre direction) dOmega(pixel)
// with the exact per-pixel solid angles of probes::Probe (they sum to 4 pi). Rows are summed
// in parallel into per-row partials, then reduced in row order, so the result is the same
// bytes for any thread count.
#pragma once

#include "probes/probe.h"

#include <Eigen/Core>

namespace prt {

using ShLighting = Eigen::Matrix<double, Eigen::Dynamic, 3>;

// A probe that carries its source cube map (probes::Probe::source_cube) is projected over the
// cube's texels with their exact solid angles (prt/cube_projection.h); any other over its
// lat-long pixels.
ShLighting project(const probes::Probe& probe, int order);
// The lat-long integration alone, even for a probe resampled from a cube map.
ShLighting project_latlong(const probes::Probe& probe, int order);

// A lat-long probe whose texels are the SH expansion of `lighting` at pixel centres
// (negative values kept: the result is a signed function, not a physical probe).
probes::Probe reconstruct(const Eigen::Ref<const ShLighting>& lighting, int width, int height);

}  // namespace prt
