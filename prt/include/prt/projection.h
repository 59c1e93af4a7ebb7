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

ShLighting project(const probes::Probe& probe, int order);

// A lat-long probe whose texels are the SH expansion of `lighting` at pixel centres
// (negative values kept: the result is a signed function, not a physical probe).
probes::Probe reconstruct(const Eigen::Ref<const ShLighting>& lighting, int width, int height);

}  // namespace prt
