#include "render/slf_model.h"

#include <cmath>
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
  slf_model_checks::check_finite(texel_weights, "texel_weights");
  slf_model_checks::check_finite(view_maps, "view_maps");
}

}  // namespace render
