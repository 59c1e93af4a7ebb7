// probes/cube_map.h: environment maps stored as six square faces, as the DirectX PRT demo and
// Filament's cmgen take them.
//
// Face order and orientation are OpenGL's (GL_TEXTURE_CUBE_MAP_POSITIVE_X + i, the OpenGL 4.6
// specification's table 8.19), the convention cmgen's face files also follow:
//   face 0 px: +X   1 nx: -X   2 py: +Y   3 ny: -Y   4 pz: +Z   5 nz: -Z
// Texel (x, y) of a face (row 0 at the top of the image) has s = (x + 0.5) / N and
// t = (y + 0.5) / N; with a = 2s - 1 and b = 2t - 1 its direction is
//   px (1, -b, -a)   nx (-1, -b, a)   py (a, 1, b)   ny (a, -1, -b)   pz (a, -b, 1)   nz (-a, -b,
//   -1)
// in the engine's world frame (probes/probe.h: right-handed, +Y up).
//
// Cross layouts put the faces in a grid of N x N cells:
//   horizontal cross (4:3)      vertical cross (3:4)
//        . py .  .                  . py .
//       nx pz px nz                nx pz px
//        . ny .  .                  . ny .
//                                   . nz .     (nz turned by 180 degrees)
// so that the grid folds into the cube; cells outside the cross are ignored.
#pragma once

#include "probes/probe.h"

#include <array>
#include <vector>

namespace probes {

constexpr int kCubeFaces = 6;
// "px", "nx", "py", "ny", "pz", "nz".
const char* cube_face_name(int face);

class CubeMap {
 public:
  CubeMap() = default;
  // `faces[f]` holds size * size texels, row-major from the top row. Throws ProbeError when a
  // face has the wrong number of texels or a texel is not finite.
  CubeMap(int size, std::array<std::vector<Rgb>, kCubeFaces> faces);

  int size() const { return size_; }
  const Rgb& texel(int face, int x, int y) const {
    return faces_[std::size_t(face)][std::size_t(y) * std::size_t(size_) + std::size_t(x)];
  }

  // Direction of face coordinates (a, b) in [-1, 1]^2 (see above); not normalised.
  static Eigen::Vector3d face_direction(int face, double a, double b);
  // Unit direction of a texel's centre.
  Eigen::Vector3d texel_direction(int face, int x, int y) const;
  // Exact solid angle of a texel (the same on every face): the integral of the area element
  // (1 + a^2 + b^2)^(-3/2) over the texel, whose antiderivative is atan(ab / sqrt(1 + a^2 + b^2)).
  // The texels of all six faces sum to 4 pi.
  double texel_solid_angle(int x, int y) const;
  // Bilinear radiance lookup within the face the direction hits, clamped at the face's edges.
  Rgb lookup(const Eigen::Vector3d& direction) const;

 private:
  int size_ = 0;
  std::array<std::vector<Rgb>, kCubeFaces> faces_;
};

enum class CrossKind { kHorizontal, kVertical };

// The cube in a cross image of width x height texels (4N x 3N or 3N x 4N); throws ProbeError
// when the size does not fit the kind.
CubeMap cube_from_cross(const std::vector<Rgb>& image, int width, int height, CrossKind kind);
// The inverse, for tests and seeds; cells outside the cross are black.
std::vector<Rgb> cube_to_cross(const CubeMap& cube, CrossKind kind, int* width, int* height);

// Resampling between cube and lat-long maps (bilinear at the target's texel centres).
// The lat-long map of a cube of size N is 4N x 2N: as many texels around the equator as the
// cube has.
Probe cube_to_latlong(const CubeMap& cube, const std::string& name = {});
CubeMap latlong_to_cube(const Probe& probe, int size);

}  // namespace probes
