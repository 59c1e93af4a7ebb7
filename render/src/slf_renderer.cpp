#include "render/slf_renderer.h"

#include "background_pass.h"
#include "frame_target.h"
#include "gl_program.h"
#include "render/gl_context.h"
#include "render/supersample.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace render {

namespace slf_gl {

// Texture units, fixed in the shader's layout(binding) qualifiers.
constexpr int kClusterUnit = 0, kViewsUnit = 1, kWeightsUnit = 2, kUvUnit = 3, kPositionsUnit = 4,
              kRadianceUnit = 5, kNormalsUnit = 6;
// Texture-space shading works in square blocks of texels of this side (a multiple of
// llvmpipe's 4 x 4 shading quads).
constexpr int kBlock = 8;

// How the clusters' view maps tile one layer of the view-map array.
struct TileLayout {
  int tile_width = 0, tile_height = 0;  // Z + 2, W + 2 (the gutter)
  int columns = 0, rows = 0;            // tiles per row, rows of tiles
  int width() const { return columns * tile_width; }
  int height() const { return rows * tile_height; }
};

// Layers of the view-map array: the k + 1 slices' 3 (k + 1) floats of a direction packed
// four a texel (RGB alone would leave a quarter of every fetch unused).
int view_layers(int components) {
  return (3 * (components + 1) + 3) / 4;
}

int gl_integer(GLenum name) {
  GLint value = 0;
  glGetIntegerv(name, &value);
  return value;
}

// Near-square, within the context's texture size.
TileLayout tile_layout(const SlfModel& model, int max_size) {
  TileLayout t;
  t.tile_width = model.grid.azimuth + 2;
  t.tile_height = model.grid.elevation + 2;
  const int square = int(std::ceil(std::sqrt(double(model.clusters))));
  t.columns = std::max(1, std::min(square, max_size / t.tile_width));
  t.rows = (model.clusters + t.columns - 1) / t.columns;
  if (t.width() > max_size || t.height() > max_size) {
    std::string message = "surface light field: ";
    message += std::to_string(model.clusters);
    message += " clusters of ";
    message += std::to_string(model.grid.azimuth);
    message += " x ";
    message += std::to_string(model.grid.elevation);
    message += " view maps need a ";
    message += std::to_string(t.width());
    message += " x ";
    message += std::to_string(t.height());
    message += " texture; this context allows ";
    message += std::to_string(max_size);
    message += " per side: use fewer clusters or directions";
    throw GlError(message);
  }
  return t;
}

std::string float_literal(double value) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  std::string s(buf);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string vertex_shader() {
  return "#version 450 core\n"
         "layout(location = 0) in vec3 a_position;\n"
         "layout(location = 1) in vec2 a_uv;\n"
         "uniform mat4 u_clip_from_world;\n"
         "out vec3 v_world;\n"
         "out vec2 v_uv;\n"
         "void main() {\n"
         "  v_world = a_position;\n"
         "  v_uv = a_uv;\n"
         "  gl_Position = u_clip_from_world * vec4(a_position, 1.0);\n"
         "}\n";
}

// The deferred path's pre-pass: the atlas coordinate into colour attachment 1.
std::string uv_fragment_shader() {
  return "#version 450 core\n"
         "in vec3 v_world;\nin vec2 v_uv;\n"
         "layout(location = 1) out vec4 o_uv;\n"
         "void main() { o_uv = vec4(v_uv, 0.0, 1.0); }\n";
}

// The deferred path's shading pass: one triangle over the screen at the far plane, drawn
// with GL_GREATER so that only the pixels the pre-pass covered are shaded.
std::string fullscreen_vertex_shader() {
  return "#version 450 core\n"
         "void main() {\n"
         "  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
         "  gl_Position = vec4(p, 1.0, 1.0);\n"
         "}\n";
}

// Declarations every reconstructing shader shares: the textures and the sizes, all literal.
std::string reconstruction_declarations(const SlfModel& model, const TileLayout& tiles) {
  const int k = model.components;
  std::string s;
  s += "layout(binding = " + std::to_string(kClusterUnit) + ") uniform isampler2D u_cluster;\n";
  s += "layout(binding = " + std::to_string(kViewsUnit) + ") uniform sampler2DArray u_views;\n";
  if (k > 0)
    s += "layout(binding = " + std::to_string(kWeightsUnit) +
         ") uniform sampler2DArray u_weights;\n";
  s += "const vec2 kMap = vec2(" + float_literal(model.map_width) + ", " +
       float_literal(model.map_height) + ");\n";
  s += "const ivec2 kMapMax = ivec2(" + std::to_string(model.map_width - 1) + ", " +
       std::to_string(model.map_height - 1) + ");\n";
  s += "const vec2 kTile = vec2(" + float_literal(tiles.tile_width) + ", " +
       float_literal(tiles.tile_height) + ");\n";
  s += "const vec2 kAtlasScale = vec2(" + float_literal(1.0 / tiles.width()) + ", " +
       float_literal(1.0 / tiles.height()) + ");\n";
  s += "const int kTileColumns = " + std::to_string(tiles.columns) + ";\n";
  // Where (xi1, xi2) falls in a tile, in texels: column i's centre at 1 + i + 0.5.
  s += "const vec2 kGridScale = vec2(" + float_literal(0.5 * model.grid.azimuth) + ", " +
       float_literal(model.grid.elevation) + ");\n";
  s += "const float kInvPi = " + float_literal(1.0 / 3.14159265358979323846) + ";\n";
  s +=
      "const float kInvPolarSpan = " + float_literal(1.0 / prt::slf_polar_span(model.grid)) + ";\n";
  // A view into the grid's axes at the texel's normal n: prt::slf_grid_space, in float.
  if (model.grid.space == prt::SlfDirectionSpace::kReflected)
    s += "vec3 grid_space(vec3 d, vec3 n) { return reflect(-d, n); }\n";
  if (model.grid.space == prt::SlfDirectionSpace::kLocal)
    s += "vec3 grid_space(vec3 d, vec3 n) {\n"
         "  vec3 t = vec3(0.0, 1.0, 0.0) - n.y * n;\n"
         "  if (dot(t, t) < 1e-8) t = vec3(0.0, 0.0, -1.0) + n.z * n;\n"
         "  t = normalize(t);\n"
         "  return vec3(dot(cross(t, n), d), dot(n, d), -dot(t, d));\n"
         "}\n";
  return s;
}

// From the direction `d` in the grid's axes (the view, its mirror image or the view in the
// texel's frame) to `p`, its place in a view-map tile.
std::string direction_to_tile(const std::string& indent, const std::string& d = "d") {
  // Eq. 2; atan(0, 0) is undefined in GLSL, 0 on the CPU.
  return indent + "float azimuth = (" + d + ".x == 0.0 && " + d + ".z == 0.0) ? 0.0 : atan(" + d +
         ".x, -" + d + ".z);\n" + indent +
         "vec2 xi = vec2(1.0 + azimuth * kInvPi, min(acos(clamp(" + d +
         ".y, -1.0, 1.0)) * kInvPolarSpan, 1.0));\n" + indent +
         "vec2 p = vec2(1.0) + xi * kGridScale;\n";
}

// Adds to `l` cluster `t`'s reconstruction at `p` with the mean's coefficient `a0` and the
// components' in `u0`, `u1`, ... (four a vec4). The k + 1 slices' RGB values are packed four
// floats a texel (view_layers).
std::string view_sum(int k, const std::string& indent) {
  std::string s = indent +
                  "vec2 q = (vec2(t % kTileColumns, t / kTileColumns) * kTile + p) * "
                  "kAtlasScale;\n";
  const int view_layers = slf_gl::view_layers(k);
  for (int v = 0; v < view_layers; ++v)
    s += indent + "vec4 t" + std::to_string(v) + " = textureLod(u_views, vec3(q, " +
         float_literal(v) + "), 0.0);\n";
  for (int f = 0; f < 3 * (k + 1); ++f) {
    const int slice = f / 3, channel = f % 3;
    std::string coefficient = "a0";
    if (slice > 0) {
      coefficient = "u";  // appended: GCC 12's -Wstringop-overflow misfires on "u" + string
      coefficient += std::to_string((slice - 1) / 4);
      coefficient += '.';
      coefficient += "xyzw"[(slice - 1) % 4];
    }
    s += indent + "l.";
    s += "xyz"[channel];
    s += " += " + coefficient + " * t" + std::to_string(f / 4) + "." + "xyzw"[f % 4] + ";\n";
  }
  return s;
}

// Every size is a literal, and the sums over components are written out, so the compiler
// sees constant layer indices (llvmpipe runs such code markedly faster than loops over
// uniforms, render/shader_source.h). textureLod throughout: the fetches sit in a loop with
// a non-uniform trip count, where implicit derivatives are undefined, and there are no
// mipmaps.
//
// The four texels are reconstructed cluster by cluster, in a loop over the distinct
// clusters among them: an iteration takes the first texel not yet summed, gathers the
// bilinear weights of every texel of its cluster, interpolates their weight vectors with
// them and reads that cluster's k + 1 view-map slices once. Where the four share a cluster
// (all but the fragments on cluster borders) one iteration does it all: k + 1 view fetches
// instead of 4 (k + 1), the same sum by linearity. A loop rather than an if: llvmpipe runs
// both sides of a branch for its whole SIMD group, but leaves a loop as soon as no lane of
// the group needs another iteration, so the common case pays for one reconstruction only.
// Without `shared`, each iteration takes one texel (four iterations where all are used).
// A grid of reflected or local directions takes one texel an iteration too: each texel takes
// the fragment's direction into the grid's space at its own normal (the CPU reference's
// slf_radiance), so the four have four places in the view maps.
// Deferred: the atlas coordinate comes from the uv pre-pass's texture and the direction from
// the pixel's ray (the CPU reference's Camera::pixel_direction, reversed).
std::string fragment_shader(const SlfModel& model, const TileLayout& tiles, bool shared,
                            bool deferred) {
  const int k = model.components, layers = (k + 3) / 4;
  const bool per_texel = prt::slf_grid_uses_normals(model.grid);
  shared = shared && !per_texel;
  std::string s = "#version 450 core\n";
  s += "layout(location = 0) out vec4 o_colour;\n";
  if (per_texel)
    s += "layout(binding = " + std::to_string(kNormalsUnit) + ") uniform sampler2D u_normals;\n";
  if (deferred) {
    s += "layout(binding = " + std::to_string(kUvUnit) + ") uniform sampler2D u_uv;\n";
    s += "uniform vec3 u_forward, u_right, u_up;\nuniform vec2 u_pixel_scale;\n";
  } else {
    s += "in vec3 v_world;\nin vec2 v_uv;\nuniform vec3 u_eye;\n";
  }
  s += reconstruction_declarations(model, tiles);
  s += "void main() {\n";
  if (deferred)
    s += "  vec2 v_uv = texelFetch(u_uv, ivec2(gl_FragCoord.xy), 0).xy;\n"
         "  vec2 ndc = gl_FragCoord.xy * u_pixel_scale - 1.0;\n"
         "  vec3 d = -normalize(u_forward + ndc.x * u_right + ndc.y * u_up);\n";
  else
    s += "  vec3 d = normalize(u_eye - v_world);\n";
  if (!per_texel) s += direction_to_tile("  ");
  s += "  vec2 st = v_uv * kMap - 0.5;\n"
       "  vec2 b = floor(st);\n"
       "  vec2 f = st - b;\n"
       "  ivec2 lo = clamp(ivec2(b), ivec2(0), kMapMax);\n"
       "  ivec2 hi = clamp(ivec2(b) + 1, ivec2(0), kMapMax);\n"
       // Texels (lo.x, lo.y), (hi.x, lo.y), (lo.x, hi.y), (hi.x, hi.y) as x, y, z, w.
       "  ivec4 c = textureGather(u_cluster, (b + 1.0) / kMap).wzxy;\n"
       "  vec4 w = vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * "
       "f.y);\n"
       // Texels left to sum: used (cluster >= 0) and of non-zero weight.
       "  vec4 left = vec4(greaterThanEqual(c, ivec4(0))) * vec4(greaterThan(w, vec4(0.0)));\n";
  const char* corner[4] = {"lo", "ivec2(hi.x, lo.y)", "ivec2(lo.x, hi.y)", "hi"};
  for (int i = 0; i < 4; ++i)
    for (int l = 0; l < layers; ++l)
      s += "  vec4 u" + std::to_string(i) + "_" + std::to_string(l) +
           " = texelFetch(u_weights, ivec3(" + corner[i] + ", " + std::to_string(l) + "), 0);\n";
  s += "  vec3 l = vec3(0.0);\n"
       "  do {\n"
       "    int cl = left.x > 0.0 ? c.x : left.y > 0.0 ? c.y : left.z > 0.0 ? c.z : c.w;\n";
  if (shared) {
    s += "    vec4 take = left * vec4(equal(c, ivec4(cl)));\n";
  } else {
    s += "    vec4 take = left.x > 0.0 ? vec4(1, 0, 0, 0) : left.y > 0.0 ? vec4(0, 1, 0, 0)\n"
         "              : left.z > 0.0 ? vec4(0, 0, 1, 0) : left;\n";
  }
  if (per_texel) {
    s += "    ivec2 at = take.x > 0.0 ? lo : take.y > 0.0 ? ivec2(hi.x, lo.y)\n"
         "             : take.z > 0.0 ? ivec2(lo.x, hi.y) : hi;\n"
         "    vec3 r = grid_space(d, texelFetch(u_normals, at, 0).xyz);\n";
    s += direction_to_tile("    ", "r");
  }
  s += "    left -= take;\n"
       "    vec4 m = take * w;\n"
       "    int t = max(cl, 0);\n"
       "    float a0 = m.x + m.y + m.z + m.w;\n";
  for (int l = 0; l < layers; ++l) {
    const std::string n = std::to_string(l);
    s += "    vec4 u" + n + " = m.x * u0_" + n + " + m.y * u1_" + n + " + m.z * u2_" + n +
         " + m.w * u3_" + n + ";\n";
  }
  // Slice 0's coefficient is the weights' sum, slice 1 + j's the interpolated weight j.
  s += view_sum(k, "    ");
  // Negative radiance clamped after the spatial blend, as render/slf_reference.h explains.
  s += "  } while (any(greaterThan(left, vec4(0.0))));\n"
       "  o_colour = vec4(max(l, vec3(0.0)), 1.0);\n"
       "}\n";
  return s;
}

// Texture space, first pass: one quad per 8 x 8 block in view (an instance each, the
// block's corner texel as the attribute) over the radiance map.
std::string block_vertex_shader(const SlfModel& model) {
  return "#version 450 core\n"
         "layout(location = 0) in ivec2 a_block;\n"
         "void main() {\n"
         "  vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1);\n"
         "  vec2 texel = vec2(a_block) + corner * " +
         float_literal(kBlock) +
         ";\n"
         "  gl_Position = vec4(texel / vec2(" +
         float_literal(model.map_width) + ", " + float_literal(model.map_height) +
         ") * 2.0 - 1.0, 0.0, 1.0);\n"
         "}\n";
}

// Texture space: the texel's own reconstruction toward the eye from its surface point
// (into the grid's space at the texel's normal for reflected or local directions), unclamped (the
// clamp follows the spatial blend, in the mesh's pass). Unused texels are 0, as the blend leaves
// them out. A loop of at most one iteration rather than an if, so that a 4 x 4 group of unused
// texels skips the work (see fragment_shader).
std::string texel_fragment_shader(const SlfModel& model, const TileLayout& tiles) {
  const int k = model.components, layers = (k + 3) / 4;
  std::string s = "#version 450 core\n";
  s += "layout(location = 0) out vec4 o_colour;\nuniform vec3 u_eye;\n";
  s += "layout(binding = " + std::to_string(kPositionsUnit) + ") uniform sampler2D u_positions;\n";
  const bool per_texel = prt::slf_grid_uses_normals(model.grid);
  if (per_texel)
    s += "layout(binding = " + std::to_string(kNormalsUnit) + ") uniform sampler2D u_normals;\n";
  s += reconstruction_declarations(model, tiles);
  s += "void main() {\n"
       "  ivec2 texel = ivec2(gl_FragCoord.xy);\n"
       "  int t = texelFetch(u_cluster, texel, 0).r;\n"
       "  vec3 l = vec3(0.0);\n"
       "  for (int once = t >= 0 ? 1 : 0; once > 0; --once) {\n"
       "    vec3 d = normalize(u_eye - texelFetch(u_positions, texel, 0).xyz);\n";
  if (per_texel) s += "    d = grid_space(d, texelFetch(u_normals, texel, 0).xyz);\n";
  s += direction_to_tile("    ");
  s += "    float a0 = 1.0;\n";
  for (int l = 0; l < layers; ++l)
    s += "    vec4 u" + std::to_string(l) + " = texelFetch(u_weights, ivec3(texel, " +
         std::to_string(l) + "), 0);\n";
  s += view_sum(k, "    ");
  s += "  }\n"
       "  o_colour = vec4(l, 1.0);\n"
       "}\n";
  return s;
}

// Texture space, the mesh's pass: the radiance map's bilinear fetch at the atlas coordinate
// (texel centres at (x + 0.5) / X, clamped at the border: slf_reference's blend).
std::string radiance_fragment_shader() {
  return "#version 450 core\n"
         "in vec3 v_world;\nin vec2 v_uv;\n"
         "layout(location = 0) out vec4 o_colour;\n"
         "layout(binding = " +
         std::to_string(kRadianceUnit) +
         ") uniform sampler2D u_radiance;\n"
         "void main() {\n"
         "  o_colour = vec4(max(textureLod(u_radiance, v_uv, 0.0).rgb, vec3(0.0)), 1.0);\n"
         "}\n";
}

// The screen path the context suits: deferred on a software rasterizer (render/slf_renderer.h).
SlfShading screen_shading(const SlfRendererOptions& options) {
  if (options.shading == SlfShading::kOnePass || options.shading == SlfShading::kDeferred)
    return options.shading;
  return current_gl_info().software_rasterizer() ? SlfShading::kDeferred : SlfShading::kOnePass;
}

// What SlfRenderer::shading() says before the first frame.
SlfShading first_shading(const SlfRendererOptions& options) {
  if (options.shading == SlfShading::kAutomatic) return SlfShading::kTextureSpace;
  return options.shading == SlfShading::kTextureSpace ? options.shading : screen_shading(options);
}

// An 8 x 8 block of the surface map that some triangle's lookups read, with what decides
// whether any of those triangles can be seen: a cone around `axis` holding their face
// normals (cos and sin of its half-angle; cos -1 where they face every way) and a sphere
// holding their corners.
struct TexelBlock {
  std::int32_t x = 0, y = 0;  // its first texel
  Eigen::Vector3d axis = Eigen::Vector3d::Zero(), centre = Eigen::Vector3d::Zero();
  double cone_cos = -1, cone_sin = 0, radius = 0;
};

// The blocks holding the texels each triangle's bilinear lookups can read (its uv box, one
// texel wider on the high side, in texel indices as the lookup floors them). Two passes over
// the triangles: the normals' mean direction and the corners' box first, then the widest
// angle from that direction.
std::vector<TexelBlock> texel_blocks(const SlfModel& model) {
  const int columns = (model.map_width + kBlock - 1) / kBlock;
  const int rows = (model.map_height + kBlock - 1) / kBlock;
  const std::size_t count = std::size_t(columns) * std::size_t(rows);
  const std::size_t triangles = model.positions.size() / 3;
  // Calls visit(block index) for every block triangle t's lookups read.
  const auto for_each_block = [&](std::size_t t, const auto& visit) {
    double lo_x = 1e30, lo_y = 1e30, hi_x = -1e30, hi_y = -1e30;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector2f uv = model.uv[3 * t + std::size_t(i)];
      lo_x = std::min(lo_x, double(uv.x()) * model.map_width - 0.5);
      hi_x = std::max(hi_x, double(uv.x()) * model.map_width - 0.5);
      lo_y = std::min(lo_y, double(uv.y()) * model.map_height - 0.5);
      hi_y = std::max(hi_y, double(uv.y()) * model.map_height - 0.5);
    }
    const int x0 = std::clamp(int(std::floor(lo_x)), 0, model.map_width - 1) / kBlock;
    const int x1 = std::clamp(int(std::floor(hi_x)) + 1, 0, model.map_width - 1) / kBlock;
    const int y0 = std::clamp(int(std::floor(lo_y)), 0, model.map_height - 1) / kBlock;
    const int y1 = std::clamp(int(std::floor(hi_y)) + 1, 0, model.map_height - 1) / kBlock;
    for (int by = y0; by <= y1; ++by)
      for (int bx = x0; bx <= x1; ++bx)
        visit(std::size_t(by) * std::size_t(columns) + std::size_t(bx));
  };
  std::vector<Eigen::Vector3d> normals(triangles);
  std::vector<Eigen::Vector3d> normal_sum(count, Eigen::Vector3d::Zero());
  std::vector<Eigen::AlignedBox3d> box(count);
  std::vector<bool> read(count, false), unoriented(count, false);
  for (std::size_t t = 0; t < triangles; ++t) {
    const Eigen::Vector3d p0 = model.positions[3 * t].cast<double>();
    const Eigen::Vector3d p1 = model.positions[3 * t + 1].cast<double>();
    const Eigen::Vector3d p2 = model.positions[3 * t + 2].cast<double>();
    const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
    normals[t] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
    for_each_block(t, [&](std::size_t b) {
      read[b] = true;
      unoriented[b] = unoriented[b] || normals[t].isZero();  // never culled
      normal_sum[b] += normals[t];
      box[b].extend(p0).extend(p1).extend(p2);
    });
  }
  std::vector<Eigen::Vector3d> axis(count, Eigen::Vector3d::Zero());
  std::vector<double> lowest(count, 1.0);
  for (std::size_t b = 0; b < count; ++b)
    if (normal_sum[b].norm() > 1e-9) axis[b] = normal_sum[b].normalized();
  for (std::size_t t = 0; t < triangles; ++t)
    for_each_block(
        t, [&](std::size_t b) { lowest[b] = std::min(lowest[b], normals[t].dot(axis[b])); });
  std::vector<TexelBlock> blocks;
  for (std::size_t b = 0; b < count; ++b) {
    if (!read[b]) continue;
    TexelBlock block;
    block.x = std::int32_t(b % std::size_t(columns)) * kBlock;
    block.y = std::int32_t(b / std::size_t(columns)) * kBlock;
    block.centre = box[b].center();
    block.radius = 0.5 * box[b].diagonal().norm();
    if (!unoriented[b] && !axis[b].isZero()) {
      block.axis = axis[b];
      block.cone_cos = std::clamp(lowest[b], -1.0, 1.0);
      block.cone_sin = std::sqrt(std::max(0.0, 1.0 - block.cone_cos * block.cone_cos));
    }
    blocks.push_back(block);
  }
  return blocks;
}

// Whether a block's triangles may all face away from `eye` (the eye behind every one of
// their planes): n . (eye - p) <= n . (eye - centre) + radius, whose largest value over the
// cone is |v| cos(max(0, phi - theta)) + radius, phi the angle between the axis and v.
bool faces_away(const TexelBlock& block, const Eigen::Vector3d& eye) {
  if (block.cone_cos <= -1) return false;
  const Eigen::Vector3d v = eye - block.centre;
  const double distance = v.norm();
  if (distance <= block.radius) return false;
  const double cos_phi = block.axis.dot(v) / distance;
  if (cos_phi >= block.cone_cos) return false;  // phi <= theta: a normal may point at the eye
  const double sin_phi = std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi));
  const double cos_gap = cos_phi * block.cone_cos + sin_phi * block.cone_sin;  // cos(phi - theta)
  return distance * cos_gap + block.radius < 0.0;
}

// The view frustum's six planes (Gribb and Hartmann's rows of the clip matrix), normalised so
// that n . x + w is the signed distance of x.
std::vector<Eigen::Vector4d> frustum_planes(const Eigen::Matrix4d& clip_from_world) {
  std::vector<Eigen::Vector4d> planes;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0}) {
      const Eigen::Vector4d plane = clip_from_world.row(3) + sign * clip_from_world.row(axis);
      const double length = plane.head<3>().norm();
      if (length > 0.0) planes.push_back(plane / length);
    }
  return planes;
}

// Whether a block's sphere lies wholly outside one of the planes.
bool outside_frustum(const TexelBlock& block, const std::vector<Eigen::Vector4d>& planes) {
  for (const Eigen::Vector4d& plane : planes)
    if (plane.head<3>().dot(block.centre) + plane.w() < -block.radius) return true;
  return false;
}

void texture_parameters(GLenum target, GLint filter) {
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(target, GL_TEXTURE_BASE_LEVEL, 0);
  glTexParameteri(target, GL_TEXTURE_MAX_LEVEL, 0);
}

}  // namespace slf_gl

struct SlfRenderer::Impl {
  Impl(const SlfModel& model, const probes::Probe* probe, const SlfRendererOptions& options);
  ~Impl();
  void build_programs();
  void draw(const Camera& camera);
  void draw_deferred(const Camera& camera);
  void draw_mesh(GlProgram& with, const Camera& camera);
  // Texture space: the blocks in view, in `visible_blocks` (x, y pairs), and their texels.
  void find_visible_blocks(const Camera& camera);
  long long texels_in_view() const {
    return (long long)(visible_blocks.size() / 2) * slf_gl::kBlock * slf_gl::kBlock;
  }
  void shade_texels(const Camera& camera);
  SlfShading choose(const Camera& camera);
  void bind_textures();

  SlfRendererOptions options;
  SlfShading screen = SlfShading::kOnePass;  // the screen path (options and context)
  SlfShading last = SlfShading::kOnePass;    // the last frame's path
  SlfModel shape;                            // sizes only (the arrays are uploaded and dropped)
  slf_gl::TileLayout tiles;
  GLuint vao = 0, vbo = 0, cluster_texture = 0, views_texture = 0, weights_texture = 0;
  GLuint uv_texture = 0;  // deferred: the pre-pass's atlas coordinates, at the frame's size
  int uv_width = 0, uv_height = 0;
  GLsizei vertex_count = 0;
  // Texture space: texel points, the radiance map and its framebuffer, the block instances.
  GLuint positions_texture = 0, radiance_texture = 0, radiance_fbo = 0;
  GLuint normals_texture = 0;  // reflected or local directions: each texel's normal
  GLuint block_vao = 0, block_vbo = 0;
  std::vector<slf_gl::TexelBlock> blocks;
  std::vector<std::int32_t> visible_blocks;
  // Fragments the last frame's mesh shaded (a sample query), for the automatic choice;
  // negative before the first frame.
  GLuint samples_query = 0;
  long long last_samples = -1;
  int counted_width = 0, counted_height = 0;  // the frame size last_samples was counted at
  GlProgram program, uv_program, texel_program, radiance_program;
  BackgroundPass background_pass;
  Background background;
  FrameTarget target;
};

SlfRenderer::Impl::Impl(const SlfModel& model, const probes::Probe* probe,
                        const SlfRendererOptions& renderer_options)
    : options(renderer_options),
      screen(slf_gl::screen_shading(renderer_options)),
      last(slf_gl::first_shading(renderer_options)),
      background_pass(probe) {
  model.validate();
  shape.map_width = model.map_width;
  shape.map_height = model.map_height;
  shape.grid = model.grid;
  shape.components = model.components;
  shape.clusters = model.clusters;
  const int max_size = slf_gl::gl_integer(GL_MAX_TEXTURE_SIZE);
  const int max_layers = slf_gl::gl_integer(GL_MAX_ARRAY_TEXTURE_LAYERS);
  if (model.map_width > max_size || model.map_height > max_size)
    throw GlError("surface light field: the " + std::to_string(model.map_width) + " x " +
                  std::to_string(model.map_height) + " surface map exceeds this context's " +
                  std::to_string(max_size) + " texels per side");
  if (model.components + 1 > max_layers)
    throw GlError("surface light field: " + std::to_string(model.components) + " components need " +
                  std::to_string(model.components + 1) + " texture layers; this context allows " +
                  std::to_string(max_layers));
  tiles = slf_gl::tile_layout(model, max_size);

  // Geometry: position and atlas coordinate per corner, drawn as triangles in order.
  std::vector<float> vertices;
  vertices.reserve(model.positions.size() * 5);
  for (std::size_t i = 0; i < model.positions.size(); ++i) {
    vertices.insert(vertices.end(), model.positions[i].data(), model.positions[i].data() + 3);
    vertices.insert(vertices.end(), model.uv[i].data(), model.uv[i].data() + 2);
  }
  vertex_count = GLsizei(model.positions.size());
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 5 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 5 * sizeof(float),
                        reinterpret_cast<const void*>(3 * sizeof(float)));
  glBindVertexArray(0);

  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  const int x_size = model.map_width, y_size = model.map_height;
  const std::size_t texels = std::size_t(x_size) * std::size_t(y_size);
  // Integer textures must be sampled NEAREST (otherwise incomplete); texelFetch ignores it.
  glGenTextures(1, &cluster_texture);
  glBindTexture(GL_TEXTURE_2D, cluster_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32I, x_size, y_size, 0, GL_RED_INTEGER, GL_INT,
               model.texel_cluster.data());
  slf_gl::texture_parameters(GL_TEXTURE_2D, GL_NEAREST);

  const int k = model.components;
  if (k > 0) {
    const int layers = (k + 3) / 4;
    std::vector<float> weights(texels * 4 * std::size_t(layers), 0.f);
    for (std::size_t t = 0; t < texels; ++t) {
      if (model.texel_cluster[t] < 0) continue;  // zero, whatever the model holds
      for (int j = 0; j < k; ++j)
        weights[(std::size_t(j / 4) * texels + t) * 4 + std::size_t(j % 4)] =
            model.texel_weights[t * std::size_t(k) + std::size_t(j)];
    }
    glGenTextures(1, &weights_texture);
    glBindTexture(GL_TEXTURE_2D_ARRAY, weights_texture);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA32F, x_size, y_size, layers, 0, GL_RGBA, GL_FLOAT,
                 weights.data());
    slf_gl::texture_parameters(GL_TEXTURE_2D_ARRAY, GL_NEAREST);  // texelFetch only
  }

  // View maps: float f = 3 s + channel of slice s (0 the mean, 1 + j component j) in
  // component f % 4 of layer f / 4, so that a direction's 3 (k + 1) floats take
  // ceil(3 (k + 1) / 4) fetches. Cluster c's tile sits at (c % columns, c / columns); inside
  // a tile, texel (1 + i, 1 + j) is direction (i, j), the columns 0 and Z + 1 repeat
  // directions Z - 1 and 0 (the azimuth wraps around) and the rows 0 and W + 1 repeat rows 0
  // and W - 1 (the poles clamp).
  const int z = model.grid.azimuth, w = model.grid.elevation;
  const int view_layers = slf_gl::view_layers(k);
  const std::size_t layer_texels = std::size_t(tiles.width()) * std::size_t(tiles.height());
  std::vector<float> views(layer_texels * 4 * std::size_t(view_layers), 0.f);
  for (int slice = 0; slice <= k; ++slice)
    for (int c = 0; c < model.clusters; ++c) {
      const float* v = model.view_slice(c, slice);
      const int x0 = (c % tiles.columns) * tiles.tile_width;
      const int y0 = (c / tiles.columns) * tiles.tile_height;
      for (int ty = 0; ty < tiles.tile_height; ++ty) {
        const int j = std::clamp(ty - 1, 0, w - 1);
        for (int tx = 0; tx < tiles.tile_width; ++tx) {
          const int i = (tx - 1 + z) % z;
          const float* rgb = v + (std::size_t(j) * std::size_t(z) + std::size_t(i)) * 3;
          const std::size_t texel =
              std::size_t(y0 + ty) * std::size_t(tiles.width()) + std::size_t(x0 + tx);
          for (int channel = 0; channel < 3; ++channel) {
            const std::size_t f = std::size_t(3 * slice + channel);
            views[((f / 4) * layer_texels + texel) * 4 + f % 4] = rgb[channel];
          }
        }
      }
    }
  glGenTextures(1, &views_texture);
  glBindTexture(GL_TEXTURE_2D_ARRAY, views_texture);
  glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_RGBA32F, tiles.width(), tiles.height(), view_layers, 0,
               GL_RGBA, GL_FLOAT, views.data());
  slf_gl::texture_parameters(GL_TEXTURE_2D_ARRAY, GL_LINEAR);
  check_gl("SlfRenderer: textures");

  // Texture space: each texel's surface point, and the radiance map it shades into (zero
  // until a frame writes it; texels never written are read with weight 0 or not at all).
  std::vector<float> points(texels * 4, 0.f);
  const auto upload = [&](const std::vector<Eigen::Vector3f>& per_texel, GLuint& texture) {
    for (std::size_t t = 0; t < texels; ++t)
      for (int i = 0; i < 3; ++i) points[t * 4 + std::size_t(i)] = per_texel[t][i];
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, x_size, y_size, 0, GL_RGBA, GL_FLOAT, points.data());
    slf_gl::texture_parameters(GL_TEXTURE_2D, GL_NEAREST);
  };
  upload(model.texel_positions, positions_texture);
  if (prt::slf_grid_uses_normals(model.grid)) upload(model.texel_normals, normals_texture);
  std::fill(points.begin(), points.end(), 0.f);
  glGenTextures(1, &radiance_texture);
  glBindTexture(GL_TEXTURE_2D, radiance_texture);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, x_size, y_size, 0, GL_RGBA, GL_FLOAT, points.data());
  slf_gl::texture_parameters(GL_TEXTURE_2D, GL_LINEAR);
  glGenFramebuffers(1, &radiance_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, radiance_fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, radiance_texture, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw GlError("surface light field: this context cannot render into a " +
                  std::to_string(x_size) + " x " + std::to_string(y_size) +
                  " RGBA32F radiance map; use --slf-shading one-pass or deferred");
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  blocks = slf_gl::texel_blocks(model);
  glGenVertexArrays(1, &block_vao);
  glBindVertexArray(block_vao);
  glGenBuffers(1, &block_vbo);
  glBindBuffer(GL_ARRAY_BUFFER, block_vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(blocks.size() * 2 * sizeof(std::int32_t)), nullptr,
               GL_STREAM_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribIPointer(0, 2, GL_INT, 2 * sizeof(std::int32_t), nullptr);
  glVertexAttribDivisor(0, 1);
  glBindVertexArray(0);
  glGenQueries(1, &samples_query);
  check_gl("SlfRenderer: texture-space set-up");

  build_programs();
  background.use_probe = background_pass.has_probe();
  check_gl("SlfRenderer: set-up");
}

// The screen path's programs, and texture space's unless a screen path is asked for.
void SlfRenderer::Impl::build_programs() {
  const bool fast = options.shared_cluster_fast_path;
  program = GlProgram();
  uv_program = GlProgram();
  if (options.shading != SlfShading::kTextureSpace) {
    if (screen == SlfShading::kDeferred) {
      program =
          GlProgram("surface light field (deferred shading)", slf_gl::fullscreen_vertex_shader(),
                    slf_gl::fragment_shader(shape, tiles, fast, true));
      uv_program = GlProgram("surface light field (uv pre-pass)", slf_gl::vertex_shader(),
                             slf_gl::uv_fragment_shader());
    } else {
      program = GlProgram("surface light field", slf_gl::vertex_shader(),
                          slf_gl::fragment_shader(shape, tiles, fast, false));
    }
  }
  const bool texture_space =
      options.shading == SlfShading::kAutomatic || options.shading == SlfShading::kTextureSpace;
  if (texture_space && texel_program.id() == 0) {
    texel_program = GlProgram("surface light field (texels)", slf_gl::block_vertex_shader(shape),
                              slf_gl::texel_fragment_shader(shape, tiles));
    radiance_program = GlProgram("surface light field (radiance map)", slf_gl::vertex_shader(),
                                 slf_gl::radiance_fragment_shader());
  }
}

SlfRenderer::Impl::~Impl() {
  glDeleteBuffers(1, &vbo);
  glDeleteVertexArrays(1, &vao);
  glDeleteTextures(1, &cluster_texture);
  glDeleteTextures(1, &views_texture);
  if (weights_texture) glDeleteTextures(1, &weights_texture);
  if (uv_texture) glDeleteTextures(1, &uv_texture);
  glDeleteTextures(1, &positions_texture);
  if (normals_texture) glDeleteTextures(1, &normals_texture);
  glDeleteTextures(1, &radiance_texture);
  glDeleteFramebuffers(1, &radiance_fbo);
  glDeleteBuffers(1, &block_vbo);
  glDeleteVertexArrays(1, &block_vao);
  glDeleteQueries(1, &samples_query);
}

void SlfRenderer::Impl::bind_textures() {
  glActiveTexture(GL_TEXTURE0 + slf_gl::kClusterUnit);
  glBindTexture(GL_TEXTURE_2D, cluster_texture);
  glActiveTexture(GL_TEXTURE0 + slf_gl::kViewsUnit);
  glBindTexture(GL_TEXTURE_2D_ARRAY, views_texture);
  if (weights_texture) {
    glActiveTexture(GL_TEXTURE0 + slf_gl::kWeightsUnit);
    glBindTexture(GL_TEXTURE_2D_ARRAY, weights_texture);
  }
  if (normals_texture) {
    glActiveTexture(GL_TEXTURE0 + slf_gl::kNormalsUnit);
    glBindTexture(GL_TEXTURE_2D, normals_texture);
  }
  glActiveTexture(GL_TEXTURE0);
}

// The mesh once with a trivial shader writing its atlas coordinates (and depth), then one
// screen-sized triangle shading the covered pixels. The uv texture is attached to the frame
// target's framebuffer only while the pre-pass writes it, so the shading pass samples a
// texture that no attachment of the bound framebuffer holds (no feedback loop).
void SlfRenderer::Impl::draw_deferred(const Camera& camera) {
  if (!uv_texture || uv_width != camera.width || uv_height != camera.height) {
    if (!uv_texture) glGenTextures(1, &uv_texture);
    glBindTexture(GL_TEXTURE_2D, uv_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RG32F, camera.width, camera.height, 0, GL_RG, GL_FLOAT,
                 nullptr);
    slf_gl::texture_parameters(GL_TEXTURE_2D, GL_NEAREST);
    uv_width = camera.width;
    uv_height = camera.height;
  }
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, uv_texture, 0);
  const GLenum uv_only[2] = {GL_NONE, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, uv_only);
  draw_mesh(uv_program, camera);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, 0, 0);
  const GLenum colour_only[1] = {GL_COLOR_ATTACHMENT0};
  glDrawBuffers(1, colour_only);

  glDisable(GL_CULL_FACE);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  program.use();
  // The pixel's ray as Camera::pixel_direction forms it: forward + ndc_x t a right + ndc_y t up.
  const Eigen::Vector3d f = (camera.target - camera.eye).normalized();
  const Eigen::Vector3d r = f.cross(camera.up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  const double t = std::tan(0.5 * camera.fov_y_degrees * 3.14159265358979323846 / 180.0);
  const Eigen::Vector3f ff = f.cast<float>(), rr = (r * t * camera.aspect()).cast<float>(),
                        uu = (u * t).cast<float>();
  glUniform3f(program.uniform("u_forward"), ff.x(), ff.y(), ff.z());
  glUniform3f(program.uniform("u_right"), rr.x(), rr.y(), rr.z());
  glUniform3f(program.uniform("u_up"), uu.x(), uu.y(), uu.z());
  glUniform2f(program.uniform("u_pixel_scale"), float(2.0 / camera.width),
              float(2.0 / camera.height));
  bind_textures();
  glActiveTexture(GL_TEXTURE0 + slf_gl::kUvUnit);
  glBindTexture(GL_TEXTURE_2D, uv_texture);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(vao);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
}

// The mesh with `with`, counting its fragments when the automatic choice needs them.
void SlfRenderer::Impl::draw_mesh(GlProgram& with, const Camera& camera) {
  with.use();
  const Eigen::Matrix4f clip = camera.clip_from_world().cast<float>();
  glUniformMatrix4fv(with.uniform("u_clip_from_world"), 1, GL_FALSE, clip.data());
  const Eigen::Vector3f eye = camera.eye.cast<float>();
  glUniform3f(with.uniform("u_eye"), eye.x(), eye.y(), eye.z());
  glBindVertexArray(vao);
  const bool count = options.shading == SlfShading::kAutomatic;
  if (count) glBeginQuery(GL_SAMPLES_PASSED, samples_query);
  glDrawArrays(GL_TRIANGLES, 0, vertex_count);
  if (count) glEndQuery(GL_SAMPLES_PASSED);
  glBindVertexArray(0);
}

void SlfRenderer::Impl::find_visible_blocks(const Camera& camera) {
  visible_blocks.clear();
  const std::vector<Eigen::Vector4d> planes = slf_gl::frustum_planes(camera.clip_from_world());
  for (const slf_gl::TexelBlock& block : blocks) {
    if (options.cull_back_faces && slf_gl::faces_away(block, camera.eye)) continue;
    if (slf_gl::outside_frustum(block, planes)) continue;
    visible_blocks.push_back(block.x);
    visible_blocks.push_back(block.y);
  }
}

// Texture space's first pass: the blocks in view into the radiance map.
void SlfRenderer::Impl::shade_texels(const Camera& camera) {
  glBindFramebuffer(GL_FRAMEBUFFER, radiance_fbo);
  glViewport(0, 0, shape.map_width, shape.map_height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  const GLsizei instances = GLsizei(visible_blocks.size() / 2);
  if (instances == 0) return;
  texel_program.use();
  const Eigen::Vector3f eye = camera.eye.cast<float>();
  glUniform3f(texel_program.uniform("u_eye"), eye.x(), eye.y(), eye.z());
  bind_textures();
  glActiveTexture(GL_TEXTURE0 + slf_gl::kPositionsUnit);
  glBindTexture(GL_TEXTURE_2D, positions_texture);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(block_vao);
  glBindBuffer(GL_ARRAY_BUFFER, block_vbo);
  glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(visible_blocks.size() * sizeof(std::int32_t)),
                  visible_blocks.data());
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, instances);
  glBindVertexArray(0);
}

// Texture space when the texels to shade are no more than the fragments the screen would
// shade: the last frame's count, or before the first frame every pixel of this one.
SlfShading SlfRenderer::Impl::choose(const Camera& camera) {
  if (options.shading != SlfShading::kAutomatic && options.shading != SlfShading::kTextureSpace)
    return screen;
  find_visible_blocks(camera);
  if (options.shading == SlfShading::kTextureSpace) return SlfShading::kTextureSpace;
  const long long texels = texels_in_view();
  // A frame of another size says little about this one's fragments.
  if (camera.width != counted_width || camera.height != counted_height) last_samples = -1;
  const long long fragments =
      last_samples >= 0 ? last_samples : (long long)camera.width * camera.height;
  return texels <= fragments ? SlfShading::kTextureSpace : screen;
}

void SlfRenderer::Impl::draw(const Camera& camera) {
  last = choose(camera);
  if (last == SlfShading::kTextureSpace) shade_texels(camera);
  target.bind(camera.width, camera.height);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glClearDepth(1.0);
  // As the PRT renderer: a probe background replaces the colour clear (alpha 0).
  if (background.use_probe && background_pass.has_probe()) {
    glClear(GL_DEPTH_BUFFER_BIT);
    background_pass.draw(camera, Eigen::Matrix3d::Identity());
    glDepthMask(GL_TRUE);
  } else {
    glClearColor(background.colour.x(), background.colour.y(), background.colour.z(), 0.f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
  if (options.cull_back_faces) {
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
  } else {
    glDisable(GL_CULL_FACE);
  }
  if (last == SlfShading::kDeferred) {
    draw_deferred(camera);
  } else if (last == SlfShading::kTextureSpace) {
    glActiveTexture(GL_TEXTURE0 + slf_gl::kRadianceUnit);
    glBindTexture(GL_TEXTURE_2D, radiance_texture);
    glActiveTexture(GL_TEXTURE0);
    draw_mesh(radiance_program, camera);
  } else {
    bind_textures();
    draw_mesh(program, camera);
  }
  glDisable(GL_CULL_FACE);
}

SlfRenderer::SlfRenderer(const SlfModel& model, const probes::Probe* probe,
                         const SlfRendererOptions& options)
    : impl_(std::make_unique<Impl>(model, probe, options)) {}

SlfRenderer::~SlfRenderer() = default;

void SlfRenderer::set_background(const Background& background) {
  impl_->background = background;
}

void SlfRenderer::set_probe(const probes::Probe* probe) {
  impl_->background_pass.set_probe(probe);
}

void SlfRenderer::set_options(const SlfRendererOptions& options) {
  const bool rebuild =
      options.shared_cluster_fast_path != impl_->options.shared_cluster_fast_path ||
      options.shading != impl_->options.shading;
  impl_->options = options;
  impl_->screen = slf_gl::screen_shading(options);
  impl_->last = slf_gl::first_shading(options);
  impl_->last_samples = -1;
  if (rebuild) impl_->build_programs();
}

const SlfRendererOptions& SlfRenderer::options() const {
  return impl_->options;
}

long long SlfRenderer::texels_shaded() const {
  return impl_->last == SlfShading::kTextureSpace ? impl_->texels_in_view() : 0;
}

long long SlfRenderer::texels_in_blocks() const {
  return (long long)impl_->blocks.size() * slf_gl::kBlock * slf_gl::kBlock;
}

SlfShading SlfRenderer::shading() const {
  return impl_->last;
}

FrameTiming SlfRenderer::render(const Camera& camera) {
  camera.validate();
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  impl_->draw(camera);
  glFinish();
  if (impl_->options.shading == SlfShading::kAutomatic) {
    GLuint64 samples = 0;
    glGetQueryObjectui64v(impl_->samples_query, GL_QUERY_RESULT, &samples);
    impl_->last_samples = (long long)samples;
    impl_->counted_width = camera.width;
    impl_->counted_height = camera.height;
  }
  FrameTiming timing;
  timing.gl_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  timing.total_ms = timing.gl_ms;
  check_gl("SlfRenderer::render");
  return timing;
}

Image SlfRenderer::read_image() const {
  Image image;
  read_image(image);
  return image;
}

void SlfRenderer::read_image(Image& into) const {
  impl_->target.read(into);
}

Image render_slf_image(const SlfModel& model, const Camera& camera, const probes::Probe* probe,
                       const SlfImageOptions& options) {
  camera.validate();
  const Camera big = supersampled(camera, options.supersample);
  SlfRenderer renderer(model, probe, options.renderer);
  Background background = options.background;
  background.use_probe = background.use_probe && probe != nullptr;
  renderer.set_background(background);
  renderer.render(big);
  Image image = renderer.read_image();
  if (options.supersample == 1) return image;
  return box_downsample(image, options.supersample);
}

}  // namespace render
