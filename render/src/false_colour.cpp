// render/src/false_colour.cpp: CPU rasterisation of flat false-colour pictures, their legend,
// and an 8-bit PNG writer that keeps palette colours exact (OpenImageIO for text and PNG).
#include "render/false_colour.h"

#include "render/image.h"

#include "common/atomic_file.h"
#include "common/image_codec.h"
#include "common/output_path.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace render {
namespace fs = std::filesystem;

Picture::Picture(int w, int h, const Colour8& fill) : width(w), height(h) {
  if (w <= 0 || h <= 0)
    throw std::invalid_argument("Picture: size " + std::to_string(w) + " x " + std::to_string(h) +
                                " is empty; use a positive width and height");
  rgb.resize(std::size_t(w) * std::size_t(h) * 3);
  for (std::size_t i = 0; i < rgb.size(); i += 3) std::copy(fill.begin(), fill.end(), &rgb[i]);
}

Colour8 Picture::at(int x, int y) const {
  const std::uint8_t* p = &rgb[(std::size_t(y) * width + x) * 3];
  return {p[0], p[1], p[2]};
}

void Picture::set(int x, int y, const Colour8& c) {
  std::uint8_t* p = &rgb[(std::size_t(y) * width + x) * 3];
  p[0] = c[0];
  p[1] = c[1];
  p[2] = c[2];
}

// --- Rasterisation ---------------------------------------------------------------------------

TriangleIdBuffer rasterize_triangle_ids(const meshes::Mesh& mesh, const Camera& camera) {
  camera.validate();
  const int w = camera.width, h = camera.height;
  TriangleIdBuffer ids;
  ids.width = w;
  ids.height = h;
  const std::size_t pixels = std::size_t(w) * std::size_t(h);
  ids.triangle.assign(pixels, -1);
  ids.barycentric.assign(pixels, {0.f, 0.f, 0.f});
  ids.shade.assign(pixels, 1.f);
  std::vector<float> depth(pixels, std::numeric_limits<float>::infinity());

  const Eigen::Matrix4d clip_from_world = camera.clip_from_world();
  struct Projected {
    double x = 0, y = 0, z = 0;  // pixel coordinates (row 0 at the top) and NDC depth
    bool in_front = false;
  };
  std::vector<Projected> screen(mesh.positions.size());
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector4d c = clip_from_world * mesh.positions[v].cast<double>().homogeneous();
    Projected& s = screen[v];
    s.in_front = c.w() > 0 && c.z() >= -c.w();
    if (!s.in_front) continue;
    s.x = (c.x() / c.w() * 0.5 + 0.5) * w;
    s.y = (0.5 - c.y() / c.w() * 0.5) * h;
    s.z = c.z() / c.w();
  }

  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const meshes::Triangle& tri = mesh.triangles[t];
    const Projected& a = screen[tri[0]];
    const Projected& b = screen[tri[1]];
    const Projected& c = screen[tri[2]];
    if (!a.in_front || !b.in_front || !c.in_front) continue;
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (area == 0) continue;

    const meshes::Vec3& p0 = mesh.positions[tri[0]];
    const Eigen::Vector3d normal =
        (mesh.positions[tri[1]] - p0).cross(mesh.positions[tri[2]] - p0).cast<double>();
    const Eigen::Vector3d centroid =
        ((p0 + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.f).cast<double>();
    const Eigen::Vector3d to_eye = camera.eye - centroid;
    const double cosine =
        normal.norm() > 0 && to_eye.norm() > 0 ? normal.normalized().dot(to_eye.normalized()) : 1;
    const float shade = float(0.35 + 0.65 * std::abs(cosine));

    const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x}) - 0.5)));
    const int x1 = std::min(w - 1, int(std::ceil(std::max({a.x, b.x, c.x}) - 0.5)));
    const int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y}) - 0.5)));
    const int y1 = std::min(h - 1, int(std::ceil(std::max({a.y, b.y, c.y}) - 0.5)));
    for (int y = y0; y <= y1; ++y) {
      const double py = y + 0.5;
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5;
        // Barycentrics from signed sub-areas; dividing by the signed area makes them
        // positive inside for either winding.
        const double l0 = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
        const double l1 = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
        const double l2 = 1.0 - l0 - l1;
        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
        const float z = float(l0 * a.z + l1 * b.z + l2 * c.z);
        const std::size_t i = std::size_t(y) * w + x;
        if (!(z < depth[i])) continue;  // equal depth: the lower triangle index stays
        depth[i] = z;
        ids.triangle[i] = std::int32_t(t);
        ids.barycentric[i] = {float(l0), float(l1), float(l2)};
        ids.shade[i] = shade;
      }
    }
  }
  return ids;
}

// --- Palettes --------------------------------------------------------------------------------

Colour8 cluster_colour(std::uint32_t cluster) {
  const double golden = 0.6180339887498949;
  const double hue = std::fmod(0.11 + golden * cluster, 1.0) * 6.0;
  const double value = 1.0 - 0.2 * double(cluster % 3);
  const double saturation = 0.75;
  const int sector = int(hue) % 6;
  const double f = hue - std::floor(hue);
  const double p = value * (1 - saturation), q = value * (1 - saturation * f),
               r = value * (1 - saturation * (1 - f));
  // Which of (value, p, q, r) each of red, green and blue takes in each sixth of the hue.
  static constexpr int kPick[6][3] = {{0, 3, 1}, {2, 0, 1}, {1, 0, 3},
                                      {1, 2, 0}, {3, 1, 0}, {0, 1, 2}};
  const double levels[4] = {value, p, q, r};
  const double rgb[3] = {levels[kPick[sector][0]], levels[kPick[sector][1]],
                         levels[kPick[sector][2]]};
  return {std::uint8_t(std::lround(rgb[0] * 255)), std::uint8_t(std::lround(rgb[1] * 255)),
          std::uint8_t(std::lround(rgb[2] * 255))};
}

namespace {

Colour8 scaled(const Colour8& c, float s) {
  return {std::uint8_t(std::lround(c[0] * s)), std::uint8_t(std::lround(c[1] * s)),
          std::uint8_t(std::lround(c[2] * s))};
}

// The legend's layout scales with the picture height so it stays legible at 1280 x 948 and
// fits tiny test pictures.
struct LegendLayout {
  int margin, swatch, gap, text_size;
};
LegendLayout legend_layout(int height) {
  const int swatch = std::max(2, height / 30);
  return {std::max(1, height / 60), swatch, std::max(1, swatch / 3), swatch};
}

}  // namespace

Rect legend_swatch(int picture_height, int count) {
  const LegendLayout l = legend_layout(picture_height);
  const int y0 = l.margin + (count - 1) * (l.swatch + l.gap);
  return {l.margin, y0, l.margin + l.swatch, y0 + l.swatch};
}

// --- The two pictures --------------------------------------------------------------------------

Picture overdraw_picture(const meshes::Mesh& mesh, const Camera& camera,
                         std::span<const std::uint8_t> pass_counts, const PictureOptions& options) {
  if (pass_counts.size() != mesh.triangle_count())
    throw std::invalid_argument(
        "overdraw_picture: " + std::to_string(pass_counts.size()) + " pass counts for a mesh of " +
        std::to_string(mesh.triangle_count()) + " triangles; pass one count per triangle");
  std::array<std::uint64_t, 3> share{0, 0, 0};
  for (std::uint8_t c : pass_counts) {
    if (c == 0)
      throw std::invalid_argument(
          "overdraw_picture: a triangle has pass count 0; every triangle is drawn at least once");
    ++share[std::min<int>(c, 3) - 1];
  }
  const TriangleIdBuffer ids = rasterize_triangle_ids(mesh, camera);
  Picture picture(ids.width, ids.height, options.background);
  for (int y = 0; y < ids.height; ++y)
    for (int x = 0; x < ids.width; ++x) {
      const std::size_t i = std::size_t(y) * ids.width + x;
      if (ids.triangle[i] < 0) continue;
      const Colour8& c = kPassCountPalette[std::min<int>(pass_counts[ids.triangle[i]], 3) - 1];
      picture.set(x, y, options.shade ? scaled(c, ids.shade[i]) : c);
    }
  if (options.legend) {
    const LegendLayout l = legend_layout(picture.height);
    const double total = double(std::max<std::size_t>(1, pass_counts.size()));
    const char* labels[3] = {"1 pass", "2 passes", "3 passes"};
    for (int c = 1; c <= 3; ++c) {
      const Rect r = legend_swatch(picture.height, c);
      fill_rect(picture, r, kPassCountPalette[c - 1]);
      char text[64];
      std::snprintf(text, sizeof text, "%s (%.1f%%)", labels[c - 1],
                    100.0 * double(share[c - 1]) / total);
      draw_text(picture, r.x1 + l.gap * 2, r.y1 - std::max(1, l.swatch / 6), text, l.text_size,
                {0, 0, 0});
    }
  }
  return picture;
}

Picture cluster_picture(const meshes::Mesh& mesh, const Camera& camera,
                        std::span<const std::uint32_t> cluster_of, const PictureOptions& options) {
  if (cluster_of.size() != mesh.vertex_count())
    throw std::invalid_argument(
        "cluster_picture: " + std::to_string(cluster_of.size()) + " cluster ids for a mesh of " +
        std::to_string(mesh.vertex_count()) + " vertices; pass one id per vertex");
  const TriangleIdBuffer ids = rasterize_triangle_ids(mesh, camera);
  Picture picture(ids.width, ids.height, options.background);
  for (int y = 0; y < ids.height; ++y)
    for (int x = 0; x < ids.width; ++x) {
      const std::size_t i = std::size_t(y) * ids.width + x;
      if (ids.triangle[i] < 0) continue;
      const std::array<float, 3>& l = ids.barycentric[i];
      const int corner = int(std::max_element(l.begin(), l.end()) - l.begin());
      const Colour8 c = cluster_colour(cluster_of[mesh.triangles[ids.triangle[i]][corner]]);
      picture.set(x, y, options.shade ? scaled(c, ids.shade[i]) : c);
    }
  return picture;
}

// --- Drawing kit -----------------------------------------------------------------------------

void fill_rect(Picture& picture, Rect rect, const Colour8& colour) {
  for (int y = std::max(0, rect.y0); y < std::min(picture.height, rect.y1); ++y)
    for (int x = std::max(0, rect.x0); x < std::min(picture.width, rect.x1); ++x)
      picture.set(x, y, colour);
}

bool draw_text(Picture& picture, int x, int y, const std::string& text, int size,
               const Colour8& colour) {
  const float c[3] = {colour[0] / 255.f, colour[1] / 255.f, colour[2] / 255.f};
  return common::image_codec().draw_text(picture.rgb.data(), picture.width, picture.height, x, y,
                                         text, size, c);
}

void write_picture_png(const fs::path& path, const Picture& picture) {
  write_rgb8_png(path, picture.width, picture.height, picture.rgb, "picture");
}

}  // namespace render
