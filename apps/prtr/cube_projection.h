// apps/prtr/cube_projection.h: SH projection of a cube map over its own texels, each weighted
// by its exact solid angle (probes::CubeMap::texel_solid_angle). It sits here because it
// joins probes/ (the cube) and prt/ (the SH basis), and prt::project takes lat-long maps.
#pragma once

#include "probes/cube_map.h"
#include "prt/projection.h"

namespace prtr_app {

// L_lm = sum over texels of L(texel) Y_lm(texel centre) dOmega(texel).
prt::ShLighting project_cube(const probes::CubeMap& cube, int order);

}  // namespace prtr_app
