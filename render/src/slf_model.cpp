#include "render/slf_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace render {

namespace slf_model_checks {

[[noreturn]] void refuse(const std::string& what) {
  std::string message = "surface light field: ";
  message += what;
  throw std::invalid_argument(message);
}

void check_size(std::size_t have, std::size_t want, const char* name, const char* rule) {
  if (have == want) return;
  std::string message = name;
  message += " holds ";
  message += std::to_string(have);
  message += " values; ";
  message += rule;
  message += " needs ";
  message += std::to_string(want);
  refuse(message);
}

void check_finite(const std::vector<float>& values, const char* name) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i])) {
      std::string message = name;
      message += "[";
      message += std::to_string(i);
      message += "] is not finite (NaN or infinity); rebuild the model from finite data";
      refuse(message);
    }
}

}  // namespace slf_model_checks

void SlfModel::validate() const {
  if (positions.empty() || positions.size() % 3 != 0)
    slf_model_checks::refuse(
        "positions hold " + std::to_string(positions.size()) +
        " corners; the geometry needs 3 per triangle and at least one triangle");
  slf_model_checks::check_size(normals.size(), positions.size(), "normals",
                               "one per corner (positions)");
  slf_model_checks::check_size(uv.size(), positions.size(), "uv", "one per corner (positions)");
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!positions[i].allFinite() || !normals[i].allFinite())
      slf_model_checks::refuse("corner " + std::to_string(i) +
                               " has a non-finite position or normal");
    if (!uv[i].allFinite() || (uv[i].array() < 0.f).any() || (uv[i].array() > 1.f).any())
      slf_model_checks::refuse("uv of corner " + std::to_string(i) +
                               " is outside [0, 1]^2 or not finite");
  }
  if (map_width < 1 || map_height < 1 || map_width > 16384 || map_height > 16384)
    slf_model_checks::refuse("the surface map is " + std::to_string(map_width) + " x " +
                             std::to_string(map_height) + " texels; each side must be in 1..16384");
  grid.validate();
  if (components < 0 || components > 256)
    slf_model_checks::refuse("components (k) is " + std::to_string(components) +
                             "; it must be in 0..256");
  if (clusters < 1)
    slf_model_checks::refuse("clusters (eta) is " + std::to_string(clusters) +
                             "; at least one is needed");
  const std::size_t texels = std::size_t(map_width) * std::size_t(map_height);
  slf_model_checks::check_size(texel_cluster.size(), texels, "texel_cluster",
                               "one per texel (map_width x map_height)");
  slf_model_checks::check_size(texel_weights.size(), texels * std::size_t(components),
                               "texel_weights", "map_width x map_height x components");
  slf_model_checks::check_size(
      view_maps.size(), std::size_t(clusters) * std::size_t(components + 1) * slice_floats(),
      "view_maps", "clusters x (components + 1) x azimuth x elevation x 3");
  for (std::size_t t = 0; t < texels; ++t)
    if (texel_cluster[t] < -1 || texel_cluster[t] >= clusters)
      slf_model_checks::refuse("texel " + std::to_string(t) + " (x " +
                               std::to_string(t % std::size_t(map_width)) + ", y " +
                               std::to_string(t / std::size_t(map_width)) + ") has cluster " +
                               std::to_string(texel_cluster[t]) + "; clusters run 0.." +
                               std::to_string(clusters - 1) + " (-1: unused)");
  slf_model_checks::check_size(texel_positions.size(), texels, "texel_positions",
                               "one per texel (map_width x map_height)");
  for (std::size_t t = 0; t < texels; ++t)
    if (!texel_positions[t].allFinite())
      slf_model_checks::refuse("texel_positions[" + std::to_string(t) +
                               "] is not finite; rebuild the model from finite data");
  if (prt::slf_grid_uses_normals(grid)) {
    slf_model_checks::check_size(texel_normals.size(), texels, "texel_normals",
                                 "one per texel (map_width x map_height) for reflected or local "
                                 "directions");
    for (std::size_t t = 0; t < texels; ++t)
      if (texel_cluster[t] >= 0 && !(std::abs(texel_normals[t].squaredNorm() - 1.f) < 1e-3f))
        slf_model_checks::refuse(
            "texel_normals[" + std::to_string(t) +
            "] is not a unit vector; take the normals from meshes::texel_normals");
  } else if (!texel_normals.empty()) {
    slf_model_checks::refuse(
        "texel_normals is given for a grid of view directions; only "
        "reflected and local directions use it");
  }
  slf_model_checks::check_finite(texel_weights, "texel_weights");
  slf_model_checks::check_finite(view_maps, "view_maps");
}

namespace {

// Per texel read by some triangle, where its point lies: the first corner 3 t of its triangle
// and barycentrics (u, v); corner -1 elsewhere.
struct TexelOnTriangle {
  std::int64_t corner = -1;
  float u = 0, v = 0;
};

std::vector<TexelOnTriangle> texels_on_triangles(const SlfModel& model) {
  const std::size_t texels = std::size_t(model.map_width) * std::size_t(model.map_height);
  std::vector<TexelOnTriangle> on(texels);
  // Squared uv distance (in texels) from each texel centre to the triangle giving its point.
  std::vector<float> best(texels, std::numeric_limits<float>::infinity());
  const Eigen::Vector2f scale(float(model.map_width), float(model.map_height));
  for (std::size_t t = 0; t + 2 < model.positions.size(); t += 3) {
    const Eigen::Vector2f a = model.uv[t].cwiseProduct(scale),
                          b = model.uv[t + 1].cwiseProduct(scale),
                          c = model.uv[t + 2].cwiseProduct(scale);
    const Eigen::Vector2f e1 = b - a, e2 = c - a;
    const float det = e1.x() * e2.y() - e1.y() * e2.x();
    if (det == 0.f) continue;  // no area in uv: no texel centre maps onto it
    // Texels within two of the triangle's uv box: the ones a bilinear lookup inside can read.
    const int x0 = std::max(0, int(std::floor(std::min({a.x(), b.x(), c.x()}))) - 2);
    const int x1 =
        std::min(model.map_width - 1, int(std::floor(std::max({a.x(), b.x(), c.x()}))) + 2);
    const int y0 = std::max(0, int(std::floor(std::min({a.y(), b.y(), c.y()}))) - 2);
    const int y1 =
        std::min(model.map_height - 1, int(std::floor(std::max({a.y(), b.y(), c.y()}))) + 2);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const std::size_t texel = std::size_t(y) * std::size_t(model.map_width) + std::size_t(x);
        if (model.texel_cluster[texel] < 0) continue;
        const Eigen::Vector2f q = Eigen::Vector2f(float(x) + 0.5f, float(y) + 0.5f) - a;
        float u = (q.x() * e2.y() - q.y() * e2.x()) / det;
        float v = (e1.x() * q.y() - e1.y() * q.x()) / det;
        // Onto the triangle: clamp to the barycentric simplex (near enough the nearest point
        // for the few texels outside every triangle).
        u = std::max(u, 0.f);
        v = std::max(v, 0.f);
        if (u + v > 1.f) {
          const float s = u + v;
          u /= s;
          v /= s;
        }
        const float distance = (a + u * e1 + v * e2 - (q + a)).squaredNorm();
        if (!(distance < best[texel])) continue;
        best[texel] = distance;
        on[texel] = {std::int64_t(t), u, v};
      }
  }
  return on;
}

// Corner values `of` (3 per triangle) interpolated at each texel's point.
std::vector<Eigen::Vector3f> lerp_at_texels(const SlfModel& model,
                                            const std::vector<Eigen::Vector3f>& of) {
  const std::vector<TexelOnTriangle> on = texels_on_triangles(model);
  std::vector<Eigen::Vector3f> values(on.size(), Eigen::Vector3f::Zero());
  for (std::size_t texel = 0; texel < on.size(); ++texel) {
    const TexelOnTriangle& p = on[texel];
    if (p.corner < 0) continue;
    const auto t = std::size_t(p.corner);
    values[texel] = (1.f - p.u - p.v) * of[t] + p.u * of[t + 1] + p.v * of[t + 2];
  }
  return values;
}

}  // namespace

std::vector<Eigen::Vector3f> texel_points_from_uv(const SlfModel& model) {
  return lerp_at_texels(model, model.positions);
}

std::vector<Eigen::Vector3f> texel_normals_from_uv(const SlfModel& model) {
  std::vector<Eigen::Vector3f> normals = lerp_at_texels(model, model.normals);
  for (Eigen::Vector3f& n : normals)
    n = n.norm() > 1e-6f ? Eigen::Vector3f(n.normalized()) : Eigen::Vector3f::UnitY();
  return normals;
}

}  // namespace render
