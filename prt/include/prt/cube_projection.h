// prt/cube_projection.h: SH projection of a cube map over its own texels, each weighted
// by its exact solid angle (probes::CubeMap::texel_solid_angle). prt::project (prt/projection.h)
// takes lat-long maps; this is the exact projection for cube maps.
#pragma once

#include "probes/cube_map.h"
#include "prt/projection.h"

namespace prt {

// L_lm = sum over texels of L(texel) Y_lm(texel centre) dOmega(texel).
ShLighting project_cube(const probes::CubeMap& cube, int order);

}  // namespace prt
