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
constexpr int kClusterUnit = 0, kViewsUnit = 1, kWeightsUnit = 2, kUvUnit = 3;

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
// Deferred: the atlas coordinate comes from the uv pre-pass's texture and the direction from
// the pixel's ray (the CPU reference's Camera::pixel_direction, reversed).
std::string fragment_shader(const SlfModel& model, const TileLayout& tiles, bool shared,
                            bool deferred) {
  const int k = model.components, layers = (k + 3) / 4;
  std::string s = "#version 450 core\n";
  s += "layout(location = 0) out vec4 o_colour;\n";
  if (deferred) {
    s += "layout(binding = " + std::to_string(kUvUnit) + ") uniform sampler2D u_uv;\n";
    s += "uniform vec3 u_forward, u_right, u_up;\nuniform vec2 u_pixel_scale;\n";
  } else {
    s += "in vec3 v_world;\nin vec2 v_uv;\nuniform vec3 u_eye;\n";
  }
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
  s += "void main() {\n";
  if (deferred)
    s += "  vec2 v_uv = texelFetch(u_uv, ivec2(gl_FragCoord.xy), 0).xy;\n"
         "  vec2 ndc = gl_FragCoord.xy * u_pixel_scale - 1.0;\n"
         "  vec3 d = -normalize(u_forward + ndc.x * u_right + ndc.y * u_up);\n";
  else
    s += "  vec3 d = normalize(u_eye - v_world);\n";
  s +=
      // Eq. 2; atan(0, 0) is undefined in GLSL, 0 on the CPU.
      "  float azimuth = (d.x == 0.0 && d.z == 0.0) ? 0.0 : atan(d.x, -d.z);\n"
      "  vec2 xi = vec2(1.0 + azimuth * kInvPi, acos(clamp(d.y, -1.0, 1.0)) * kInvPi);\n"
      "  vec2 p = vec2(1.0) + xi * kGridScale;\n"
      "  vec2 st = v_uv * kMap - 0.5;\n"
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
  s += "    left -= take;\n"
       "    vec4 m = take * w;\n"
       "    int t = max(cl, 0);\n"
       "    vec2 q = (vec2(t % kTileColumns, t / kTileColumns) * kTile + p) * kAtlasScale;\n"
       "    float a0 = m.x + m.y + m.z + m.w;\n";
  for (int l = 0; l < layers; ++l) {
    const std::string n = std::to_string(l);
    s += "    vec4 u" + n + " = m.x * u0_" + n + " + m.y * u1_" + n + " + m.z * u2_" + n +
         " + m.w * u3_" + n + ";\n";
  }
  // The k + 1 slices' RGB values, packed four floats a texel (view_layers); slice 0's
  // coefficient is the weights' sum, slice 1 + j's the interpolated weight j.
  const int view_layers = slf_gl::view_layers(k);
  for (int v = 0; v < view_layers; ++v)
    s += "    vec4 t" + std::to_string(v) + " = textureLod(u_views, vec3(q, " + float_literal(v) +
         "), 0.0);\n";
  for (int f = 0; f < 3 * (k + 1); ++f) {
    const int slice = f / 3, channel = f % 3;
    std::string coefficient = "a0";
    if (slice > 0) {
      coefficient = "u";  // appended: GCC 12's -Wstringop-overflow misfires on "u" + string
      coefficient += std::to_string((slice - 1) / 4);
      coefficient += '.';
      coefficient += "xyzw"[(slice - 1) % 4];
    }
    s += "    l.";
    s += "xyz"[channel];
    s += " += " + coefficient + " * t" + std::to_string(f / 4) + "." + "xyzw"[f % 4] + ";\n";
  }
  // Negative radiance clamped after the spatial blend, as render/slf_reference.h explains.
  s += "  } while (any(greaterThan(left, vec4(0.0))));\n"
       "  o_colour = vec4(max(l, vec3(0.0)), 1.0);\n"
       "}\n";
  return s;
}

// Unset, the context decides: deferred on a software rasterizer (render/slf_renderer.h).
bool resolve_deferred(const SlfRendererOptions& options) {
  return options.deferred.value_or(current_gl_info().software_rasterizer());
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
  void build_program();
  void draw(const Camera& camera);
  void draw_deferred(const Camera& camera);
  void bind_textures();

  SlfRendererOptions options;
  bool deferred = false;  // options.deferred, resolved against the context
  SlfModel shape;         // sizes only (the arrays are uploaded and dropped)
  slf_gl::TileLayout tiles;
  GLuint vao = 0, vbo = 0, cluster_texture = 0, views_texture = 0, weights_texture = 0;
  GLuint uv_texture = 0;  // deferred: the pre-pass's atlas coordinates, at the frame's size
  int uv_width = 0, uv_height = 0;
  GLsizei vertex_count = 0;
  GlProgram program, uv_program;
  BackgroundPass background_pass;
  Background background;
  FrameTarget target;
};

SlfRenderer::Impl::Impl(const SlfModel& model, const probes::Probe* probe,
                        const SlfRendererOptions& renderer_options)
    : options(renderer_options),
      deferred(slf_gl::resolve_deferred(renderer_options)),
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

  build_program();
  background.use_probe = background_pass.has_probe();
  check_gl("SlfRenderer: set-up");
}

void SlfRenderer::Impl::build_program() {
  if (deferred) {
    program =
        GlProgram("surface light field (deferred shading)", slf_gl::fullscreen_vertex_shader(),
                  slf_gl::fragment_shader(shape, tiles, options.shared_cluster_fast_path, true));
    uv_program = GlProgram("surface light field (uv pre-pass)", slf_gl::vertex_shader(),
                           slf_gl::uv_fragment_shader());
  } else {
    program =
        GlProgram("surface light field", slf_gl::vertex_shader(),
                  slf_gl::fragment_shader(shape, tiles, options.shared_cluster_fast_path, false));
  }
}

SlfRenderer::Impl::~Impl() {
  glDeleteBuffers(1, &vbo);
  glDeleteVertexArrays(1, &vao);
  glDeleteTextures(1, &cluster_texture);
  glDeleteTextures(1, &views_texture);
  if (weights_texture) glDeleteTextures(1, &weights_texture);
  if (uv_texture) glDeleteTextures(1, &uv_texture);
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
  uv_program.use();
  const Eigen::Matrix4f clip = camera.clip_from_world().cast<float>();
  glUniformMatrix4fv(uv_program.uniform("u_clip_from_world"), 1, GL_FALSE, clip.data());
  glBindVertexArray(vao);
  glDrawArrays(GL_TRIANGLES, 0, vertex_count);
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
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
}

void SlfRenderer::Impl::draw(const Camera& camera) {
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
  if (deferred) {
    draw_deferred(camera);
  } else {
    program.use();
    const Eigen::Matrix4f clip = camera.clip_from_world().cast<float>();
    glUniformMatrix4fv(program.uniform("u_clip_from_world"), 1, GL_FALSE, clip.data());
    const Eigen::Vector3f eye = camera.eye.cast<float>();
    glUniform3f(program.uniform("u_eye"), eye.x(), eye.y(), eye.z());
    bind_textures();
    glBindVertexArray(vao);
    glDrawArrays(GL_TRIANGLES, 0, vertex_count);
    glBindVertexArray(0);
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
  const bool deferred = slf_gl::resolve_deferred(options);
  const bool rebuild =
      options.shared_cluster_fast_path != impl_->options.shared_cluster_fast_path ||
      deferred != impl_->deferred;
  impl_->options = options;
  impl_->deferred = deferred;
  if (rebuild) impl_->build_program();
}

bool SlfRenderer::deferred() const {
  return impl_->deferred;
}

FrameTiming SlfRenderer::render(const Camera& camera) {
  camera.validate();
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  impl_->draw(camera);
  glFinish();
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
