// render/shader_source.h: GLSL 4.50 sources, generated for one constant layout.
//
// Why generated: on llvmpipe (measured; docs/ARCHITECTURE.md "Rendering") a vertex shader whose
// uniform indices are all compile-time constants runs ~2.9x faster than one with any non-constant
// index (a loop counter, a per-vertex cluster id, an SSBO read). So the SH basis and the CPCA sums
// are emitted as straight-line code with literal coefficients and literal register offsets; the
// only non-constant index left is the per-vertex cluster base where a path needs one.
//
// Vertex attribute locations, shared with the renderer:
//   0 position, 1 normal, 2 tangent (bitangent = normal x tangent, meshes/mesh.h),
//   3 cluster (uint: slot in its pass for multipass, cluster for single pass),
//   4 pass (uint), 5..14 weights as vec4s (ceil(N / 4) of them, so N <= 40), 15 radiance
//   for the pass-through shader (the last location every GL 4.5 context has).
// Every vertex shader declares `invariant gl_Position` and computes it by the same
// expression, so the depth pre-pass and the shading passes agree bit for bit (GL_EQUAL).
// The shading output `v_radiance` is what transform feedback captures.
#pragma once

#include "render/shading.h"

#include <string>

namespace render {

enum class ConstantAccess {
  kUniformSlot,   // UBO `Constants` of the pass; base = a_cluster * registers (multipass)
  kUniformFixed,  // UBO `Constants` of one cluster, all indices literal (decoupled)
  kStorage,       // SSBO `Constants` of all clusters; base = a_cluster * registers
};

inline constexpr int kAttrPosition = 0, kAttrNormal = 1, kAttrTangent = 2, kAttrCluster = 3,
                     kAttrPass = 4, kAttrWeights = 5, kAttrRadiance = 15;
inline constexpr int kConstantsBinding = 0;  // UBO or SSBO binding point
inline constexpr int kExitBinding = 1;       // SSBO of the uncompressed exit vectors

// Straight-line GLSL declaring `float <prefix>0 .. <prefix>(n-1)`, the real SH basis of
// prt/sh.h (same convention) at the unit vec3 named `dir`.
std::string sh_basis_glsl(int order, const std::string& dir, const std::string& prefix);

// CPCA reconstruction and SH evaluation. `slots` sizes the UBO array (clusters per pass;
// 1 for kUniformFixed; ignored for kStorage). With `pass_test`, vertices whose a_pass differs
// from uniform u_pass output zero radiance (multipass).
std::string compressed_vertex_shader(const ConstantLayout& layout, ConstantAccess access, int slots,
                                     bool pass_test);

// Exit vectors e_p from an SSBO (uncompressed path), indexed by gl_VertexID.
std::string uncompressed_vertex_shader(int order, bool glossy);

// Per-vertex radiance from attribute 15 (CPU and decoupled paths, and the bench floor).
std::string passthrough_vertex_shader();
// Position only: the depth pre-pass and the trivial-shader floor.
std::string position_vertex_shader();

std::string radiance_fragment_shader();  // vec4(v_radiance, 1)
std::string coverage_fragment_shader();  // vec4(0, 0, 0, 1): alpha = coverage
std::string constant_fragment_shader();  // uniform u_colour, alpha 1

// Full-screen triangle at depth 1 and one lookup of the probe, resampled into a cube map
// (render/src/background_pass.cpp); alpha 0 (background is not coverage). Solid colours
// are the clear colour.
std::string background_vertex_shader();
std::string background_fragment_shader();

}  // namespace render
