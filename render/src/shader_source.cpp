#include "render/shader_source.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace render {

namespace {

const char* kHeader = "#version 450 core\n";
const char* kPositionDecl =
    "layout(location = 0) in vec3 a_position;\n"
    "uniform mat4 u_clip_from_world;\n"
    "invariant gl_Position;\n";
const char* kPositionStatement = "  gl_Position = u_clip_from_world * vec4(a_position, 1.0);\n";

// Shortest text that reads back as the same float.
std::string literal(double value) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  std::string s(buf);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

double factorial_ratio(int l, int m) {  // (l - m)! / (l + m)!
  double r = 1.0;
  for (int i = l - m + 1; i <= l + m; ++i) r /= double(i);
  return r;
}

// Local view direction in the vertex frame, as `d`.
const char* kLocalView =
    "  vec3 n_ = normalize(a_normal);\n"
    "  vec3 t_ = normalize(a_tangent);\n"
    "  vec3 b_ = cross(n_, t_);\n"
    "  vec3 v_ = normalize(u_eye - a_position);\n"
    "  vec3 d = vec3(dot(v_, t_), dot(v_, b_), dot(v_, n_));\n"
    // A view below the vertex's horizon (a silhouette: the interpolated surface still faces
    // the eye) takes the radiance of its most grazing view above it (prt/view_fit.h,
    // clamp_to_horizon): the fit is defined up to the horizon, its extension is not.
    "  if (d.z < 0.0) {\n"
    "    float t_len_ = length(d.xy);\n"
    "    d = t_len_ > 0.0 ? vec3(d.xy / t_len_, 0.0) : vec3(1.0, 0.0, 0.0);\n"
    "  }\n";

}  // namespace

std::string sh_basis_glsl(int order, const std::string& dir, const std::string& prefix) {
  if (order < 1 || order > 10)
    throw std::invalid_argument("sh_basis_glsl: order " + std::to_string(order) +
                                " is outside 1..10");
  std::ostringstream o;
  const std::string x = dir + ".x", y = dir + ".y", z = dir + ".z";
  // Re/Im of (x + i y)^m carry sin^m(theta) cos/sin(m phi), so no trigonometry is needed.
  o << "  float c0_ = 1.0, s0_ = 0.0;\n";
  for (int m = 1; m < order; ++m) {
    o << "  float c" << m << "_ = " << x << " * c" << m - 1 << "_ - " << y << " * s" << m - 1
      << "_;\n";
    o << "  float s" << m << "_ = " << x << " * s" << m - 1 << "_ + " << y << " * c" << m - 1
      << "_;\n";
  }
  for (int m = 0; m < order; ++m) {
    // P~_l^m(z): associated Legendre without sin^m(theta) and without the (-1)^m phase.
    double pmm = 1.0;
    for (int k = 1; k <= m; ++k) pmm *= double(2 * k - 1);
    auto p = [&](int l) {
      std::string name = "p";
      name += std::to_string(l);
      name += '_';
      name += std::to_string(m);
      name += '_';
      return name;
    };
    o << "  float " << p(m) << " = " << literal(pmm) << ";\n";
    if (m + 1 < order)
      o << "  float " << p(m + 1) << " = " << literal(2 * m + 1) << " * " << z << " * " << p(m)
        << ";\n";
    for (int l = m + 2; l < order; ++l)
      o << "  float " << p(l) << " = " << literal(double(2 * l - 1) / (l - m)) << " * " << z
        << " * " << p(l - 1) << " - " << literal(double(l + m - 1) / (l - m)) << " * " << p(l - 2)
        << ";\n";
    for (int l = m; l < order; ++l) {
      const double k = std::sqrt((2 * l + 1) / (4 * std::numbers::pi) * factorial_ratio(l, m));
      if (m == 0) {
        o << "  float " << prefix << l * (l + 1) << " = " << literal(k) << " * " << p(l) << ";\n";
      } else {
        const std::string scale = literal(std::numbers::sqrt2 * k);
        o << "  float " << prefix << l * (l + 1) + m << " = " << scale << " * " << p(l) << " * c"
          << m << "_;\n";
        o << "  float " << prefix << l * (l + 1) - m << " = " << scale << " * " << p(l) << " * s"
          << m << "_;\n";
      }
    }
  }
  return o.str();
}

std::string compressed_vertex_shader(const ConstantLayout& layout, ConstantAccess access, int slots,
                                     bool pass_test) {
  const int registers = layout.registers_per_cluster();
  const int components = layout.terms - 1;
  const int weight_vectors = (components + 3) / 4;
  std::ostringstream o;
  o << kHeader << kPositionDecl;
  o << "layout(location = 1) in vec3 a_normal;\n"
       "layout(location = 2) in vec3 a_tangent;\n"
       "layout(location = 3) in uint a_cluster;\n"
       "layout(location = 4) in uint a_pass;\n";
  for (int i = 0; i < weight_vectors; ++i)
    o << "layout(location = " << kAttrWeights + i << ") in vec4 a_w" << i << ";\n";
  o << "uniform vec3 u_eye;\nuniform uint u_pass;\n";
  std::string base;
  if (access == ConstantAccess::kStorage) {
    o << "layout(std430, binding = " << kConstantsBinding
      << ") readonly buffer Constants { vec4 k_[]; };\n";
    base = "base_ + ";
  } else {
    const int count = registers * (access == ConstantAccess::kUniformFixed ? 1 : slots);
    o << "layout(std140, binding = " << kConstantsBinding << ") uniform Constants { vec4 k_["
      << count << "]; };\n";
    if (access == ConstantAccess::kUniformSlot) base = "base_ + ";
  }
  o << "out vec3 v_radiance;\n\nvoid main() {\n" << kPositionStatement;
  if (pass_test) o << "  if (a_pass != u_pass) { v_radiance = vec3(0.0); return; }\n";
  if (!base.empty()) o << "  int base_ = int(a_cluster) * " << registers << ";\n";
  if (layout.glossy) {
    o << kLocalView << sh_basis_glsl(layout.order, "d", "y");
  } else {
    o << "  float y0 = 1.0;\n";
  }
  static const char kComp[] = "xyzw";
  o << "  vec3 r = vec3(0.0);\n";
  for (int t = 0; t < layout.terms; ++t) {
    std::string weight;
    if (t > 0) weight = "a_w" + std::to_string((t - 1) / 4) + "." + kComp[(t - 1) % 4];
    o << "  r += ";
    if (!weight.empty()) o << weight << " * ";
    o << "vec3(";
    for (int c = 0; c < 3; ++c) {
      if (c) o << ",\n       ";
      for (int i = 0; i < layout.rows; ++i) {
        const int f = layout.offset(t, c, i);
        if (i) o << " + ";
        o << "y" << i << " * k_[" << base << f / 4 << "]." << kComp[f % 4];
      }
    }
    o << ");\n";
  }
  o << "  v_radiance = r;\n}\n";
  return o.str();
}

std::string uncompressed_vertex_shader(int order, bool glossy) {
  const int rows = glossy ? order * order : 1;
  std::ostringstream o;
  o << kHeader << kPositionDecl
    << "layout(location = 1) in vec3 a_normal;\n"
       "layout(location = 2) in vec3 a_tangent;\n"
       "uniform vec3 u_eye;\n"
       "layout(std430, binding = "
    << kExitBinding
    << ") readonly buffer Exit { float e_[]; };\n"
       "out vec3 v_radiance;\n\nvoid main() {\n"
    << kPositionStatement << "  int base_ = gl_VertexID * " << 3 * rows << ";\n";
  if (glossy)
    o << kLocalView << sh_basis_glsl(order, "d", "y");
  else
    o << "  float y0 = 1.0;\n";
  o << "  v_radiance = vec3(";
  for (int c = 0; c < 3; ++c) {
    if (c) o << ",\n      ";
    for (int i = 0; i < rows; ++i)
      o << (i ? " + " : "") << "y" << i << " * e_[base_ + " << c * rows + i << "]";
  }
  o << ");\n";
  o << "}\n";
  return o.str();
}

std::string passthrough_vertex_shader() {
  // Appended piece by piece: GCC 12 misreads this sum of literals as an out-of-bounds memcpy
  // (-Warray-bounds false positive) once the precompiled <string> is in use.
  std::string s(kHeader);
  s += kPositionDecl;
  s += "layout(location = 15) in vec3 a_radiance;\nout vec3 v_radiance;\n\nvoid main() {\n";
  s += kPositionStatement;
  s += "  v_radiance = a_radiance;\n}\n";
  return s;
}

std::string position_vertex_shader() {
  return std::string(kHeader) + kPositionDecl + "\nvoid main() {\n" + kPositionStatement + "}\n";
}

std::string radiance_fragment_shader() {
  return std::string(kHeader) +
         "in vec3 v_radiance;\nlayout(location = 0) out vec4 o_colour;\n"
         "void main() { o_colour = vec4(v_radiance, 1.0); }\n";
}

std::string coverage_fragment_shader() {
  return std::string(kHeader) +
         "layout(location = 0) out vec4 o_colour;\n"
         "void main() { o_colour = vec4(0.0, 0.0, 0.0, 1.0); }\n";
}

std::string constant_fragment_shader() {
  return std::string(kHeader) +
         "uniform vec3 u_colour;\nlayout(location = 0) out vec4 o_colour;\n"
         "void main() { o_colour = vec4(u_colour, 1.0); }\n";
}

std::string background_vertex_shader() {
  // The world ray f + x r + y u is affine in screen position, and so is its rotation into the
  // probe's frame: the corners carry the rotated ray and interpolation is exact, leaving the
  // fragment stage one tap (moving the matrix product here took the pass from about 0.5 to
  // 0.3 x the floor frame under llvmpipe).
  return std::string(kHeader) +
         "uniform vec3 u_forward, u_right, u_up;  // right/up scaled by the half-fov tangents\n"
         "uniform mat3 u_probe_from_world;\n"
         "out vec3 v_direction;\n"
         "void main() {\n"
         "  vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
         "  v_direction = u_probe_from_world * (u_forward + p.x * u_right + p.y * u_up);\n"
         "  gl_Position = vec4(p, 1.0, 1.0);\n"
         "}\n";
}

std::string background_fragment_shader() {
  // The probe arrives resampled into a cube map (background_pass.cpp): one seamless,
  // hardware-filtered tap (a cube tap needs no normalised direction). Alpha 0 is the
  // cleared coverage the pass stands in for.
  return std::string(kHeader) +
         "in vec3 v_direction;\n"
         "uniform samplerCube u_probe;\n"
         "layout(location = 0) out vec4 o_colour;\n"
         "void main() {\n"
         "  o_colour = vec4(texture(u_probe, v_direction).rgb, 0.0);\n"
         "}\n";
}

}  // namespace render
