// Cube-map geometry: face directions after the OpenGL cube-map table, and the exact texel
// solid angle from the area element of the cube face seen from its centre (M. Ihrke's
// derivation as used by AMD CubeMapGen: the solid angle of the face rectangle from the origin
// to (a, b) is atan(ab / sqrt(a^2 + b^2 + 1)), and a texel's follows by inclusion-exclusion).
#include "probes/cube_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace probes {

namespace {

// Cells (column, row) of each face in a cross, and whether the face is stored turned by 180
// degrees (see probes/cube_map.h).
struct Cell {
  int column, row;
  bool turned;
};
constexpr Cell kHorizontal[kCubeFaces] = {{2, 1, false}, {0, 1, false}, {1, 0, false},
                                          {1, 2, false}, {1, 1, false}, {3, 1, false}};
constexpr Cell kVertical[kCubeFaces] = {{2, 1, false}, {0, 1, false}, {1, 0, false},
                                        {1, 2, false}, {1, 1, false}, {1, 3, true}};

const Cell& cell_of(CrossKind kind, int face) {
  return kind == CrossKind::kHorizontal ? kHorizontal[face] : kVertical[face];
}

double area_to(double a, double b) {
  return std::atan2(a * b, std::sqrt(a * a + b * b + 1.0));
}

}  // namespace

const char* cube_face_name(int face) {
  static const char* const kNames[kCubeFaces] = {"px", "nx", "py", "ny", "pz", "nz"};
  return face >= 0 && face < kCubeFaces ? kNames[face] : "?";
}

CubeMap::CubeMap(int size, std::array<std::vector<Rgb>, kCubeFaces> faces)
    : size_(size), faces_(std::move(faces)) {
  if (size < 1) throw ProbeError("cube map: face size must be positive");
  for (int f = 0; f < kCubeFaces; ++f) {
    const std::vector<Rgb>& face = faces_[std::size_t(f)];
    if (face.size() != std::size_t(size) * std::size_t(size)) {
      throw ProbeError(std::string("cube map: face ") + cube_face_name(f) + " has " +
                       std::to_string(face.size()) + " texels, expected " +
                       std::to_string(std::size_t(size) * std::size_t(size)));
    }
    for (const Rgb& t : face) {
      if (!t.allFinite()) {
        throw ProbeError(std::string("cube map: face ") + cube_face_name(f) + " has NaN or Inf");
      }
    }
  }
}

Eigen::Vector3d CubeMap::face_direction(int face, double a, double b) {
  switch (face) {
    case 0:
      return {1.0, -b, -a};
    case 1:
      return {-1.0, -b, a};
    case 2:
      return {a, 1.0, b};
    case 3:
      return {a, -1.0, -b};
    case 4:
      return {a, -b, 1.0};
    default:
      return {-a, -b, -1.0};
  }
}

Eigen::Vector3d CubeMap::texel_direction(int face, int x, int y) const {
  const double a = 2.0 * (x + 0.5) / size_ - 1.0, b = 2.0 * (y + 0.5) / size_ - 1.0;
  return face_direction(face, a, b).normalized();
}

double CubeMap::texel_solid_angle(int x, int y) const {
  const double a0 = 2.0 * x / size_ - 1.0, a1 = 2.0 * (x + 1) / size_ - 1.0;
  const double b0 = 2.0 * y / size_ - 1.0, b1 = 2.0 * (y + 1) / size_ - 1.0;
  return area_to(a1, b1) - area_to(a0, b1) - area_to(a1, b0) + area_to(a0, b0);
}

Rgb CubeMap::lookup(const Eigen::Vector3d& d) const {
  const Eigen::Vector3d m = d.cwiseAbs();
  int face;
  double a, b;
  if (m.x() >= m.y() && m.x() >= m.z()) {
    face = d.x() > 0 ? 0 : 1;
    a = (d.x() > 0 ? -d.z() : d.z()) / m.x();
    b = -d.y() / m.x();
  } else if (m.y() >= m.z()) {
    face = d.y() > 0 ? 2 : 3;
    a = d.x() / m.y();
    b = (d.y() > 0 ? d.z() : -d.z()) / m.y();
  } else {
    face = d.z() > 0 ? 4 : 5;
    a = (d.z() > 0 ? d.x() : -d.x()) / m.z();
    b = -d.y() / m.z();
  }
  // Bilinear between texel centres, clamped to the face.
  const double fx = std::clamp((a + 1.0) * 0.5 * size_ - 0.5, 0.0, double(size_ - 1));
  const double fy = std::clamp((b + 1.0) * 0.5 * size_ - 0.5, 0.0, double(size_ - 1));
  const int x0 = int(fx), y0 = int(fy);
  const int x1 = std::min(x0 + 1, size_ - 1), y1 = std::min(y0 + 1, size_ - 1);
  const float tx = float(fx - x0), ty = float(fy - y0);
  const Rgb top = (1.0f - tx) * texel(face, x0, y0) + tx * texel(face, x1, y0);
  const Rgb bottom = (1.0f - tx) * texel(face, x0, y1) + tx * texel(face, x1, y1);
  return (1.0f - ty) * top + ty * bottom;
}

CubeMap cube_from_cross(const std::vector<Rgb>& image, int width, int height, CrossKind kind) {
  const int columns = kind == CrossKind::kHorizontal ? 4 : 3;
  const int rows = kind == CrossKind::kHorizontal ? 3 : 4;
  const int n = width / columns;
  if (n < 1 || width != columns * n || height != rows * n ||
      image.size() != std::size_t(width) * std::size_t(height)) {
    throw ProbeError(std::to_string(width) + "x" + std::to_string(height) + " is not a " +
                     std::to_string(columns) + ":" + std::to_string(rows) + " cross");
  }
  std::array<std::vector<Rgb>, kCubeFaces> faces;
  for (int f = 0; f < kCubeFaces; ++f) {
    const Cell& c = cell_of(kind, f);
    std::vector<Rgb>& face = faces[std::size_t(f)];
    face.resize(std::size_t(n) * std::size_t(n));
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const int sx = c.turned ? n - 1 - x : x, sy = c.turned ? n - 1 - y : y;
        face[std::size_t(y) * std::size_t(n) + std::size_t(x)] =
            image[std::size_t(c.row * n + sy) * std::size_t(width) +
                  std::size_t(c.column * n + sx)];
      }
    }
  }
  return CubeMap(n, std::move(faces));
}

std::vector<Rgb> cube_to_cross(const CubeMap& cube, CrossKind kind, int* width, int* height) {
  const int n = cube.size();
  *width = (kind == CrossKind::kHorizontal ? 4 : 3) * n;
  *height = (kind == CrossKind::kHorizontal ? 3 : 4) * n;
  std::vector<Rgb> image(std::size_t(*width) * std::size_t(*height), Rgb::Zero());
  for (int f = 0; f < kCubeFaces; ++f) {
    const Cell& c = cell_of(kind, f);
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const int sx = c.turned ? n - 1 - x : x, sy = c.turned ? n - 1 - y : y;
        image[std::size_t(c.row * n + sy) * std::size_t(*width) + std::size_t(c.column * n + sx)] =
            cube.texel(f, x, y);
      }
    }
  }
  return image;
}

Probe cube_to_latlong(const CubeMap& cube, const std::string& name) {
  const int width = 4 * cube.size(), height = 2 * cube.size();
  std::vector<Rgb> texels(std::size_t(width) * std::size_t(height));
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y != r.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        texels[std::size_t(y) * std::size_t(width) + std::size_t(x)] =
            cube.lookup(latlong_direction((x + 0.5) / width, (y + 0.5) / height));
      }
    }
  });
  return Probe(width, height, std::move(texels), name);
}

CubeMap latlong_to_cube(const Probe& probe, int size) {
  std::array<std::vector<Rgb>, kCubeFaces> faces;
  for (int f = 0; f < kCubeFaces; ++f) {
    std::vector<Rgb>& face = faces[std::size_t(f)];
    face.resize(std::size_t(size) * std::size_t(size));
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const double a = 2.0 * (x + 0.5) / size - 1.0, b = 2.0 * (y + 0.5) / size - 1.0;
        face[std::size_t(y) * std::size_t(size) + std::size_t(x)] =
            probe.lookup(CubeMap::face_direction(f, a, b));
      }
    }
  }
  return CubeMap(size, std::move(faces));
}

}  // namespace probes
