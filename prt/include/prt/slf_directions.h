// prt/slf_directions.h: the surface light field's grid of directions (SLF paper, Sec. 3.1).
//
// A surface light field stores exit radiance toward Z x W world-space directions over the
// whole sphere, in the paper's latitude-longitude parameterisation (its Eqs. 1 and 2, after
// Reinhard et al. 2010): xi1 in [0, 2] is the azimuth, xi2 in [0, 1] the polar angle from
// world +Y,
//   (theta, phi) = (pi (xi1 - 1), pi xi2)
//   d = (sin phi sin theta, cos phi, -sin phi cos theta)
// and back, xi1 = 1 + atan2(d.x, -d.z) / pi, xi2 = acos(d.y) / pi. The whole sphere rather
// than each point's hemisphere, so the renderer never turns a view into a local frame.
//
// Direction (i, j), azimuth cell i in [0, Z) and polar cell j in [0, W), sits at its cell's
// centre, xi1 = 2 (i + 0.5) / Z and xi2 = (j + 0.5) / W, and is column j Z + i of a row of
// the SLF matrix (times three: RGB innermost, as render/slf_model.h lays out the view maps).
//
// The grid's directions are either the views themselves (the paper's) or their mirror images
// about the point's shading normal n, r = 2 (n . v) n - v: the reflected reparameterisation
// of Wood et al. (Surface Light Fields for 3D Photography, SIGGRAPH 2000). A glossy lobe
// and the probe's features it reflects then sit at the same grid place for every point, and
// a view's angle to the normal maps to the same angle, so a rim lit from behind changes
// along the polar axis at half the angular rate. Reflection is its own inverse and keeps
// solid angle, so a cell's mean over r is its mean over the views it maps to.
//
// Both of those grids spend half their cells below each point's horizon, where no view of the
// front of the surface falls, and their cells along the horizon straddle it. The local grid
// lays the same Z x W cells over the point's hemisphere alone, in its own frame: the pole is
// the shading normal and azimuth 0 the world's up projected onto the tangent plane (the
// world's -Z where the normal is vertical), so the polar rows span [0, pi/2] and end at the
// horizon, at twice the polar resolution for the same columns. Views below the horizon (a
// shading normal turned from the eye) read the horizon's row. In that frame a view and its
// mirror image differ by half a turn of azimuth, so one local grid serves both.
#pragma once

#include "common/enum_names.h"

#include <Eigen/Core>

#include <cstdint>

namespace prt {

enum class SlfDirectionSpace : std::uint16_t { kView = 0, kReflected = 1, kLocal = 2 };
inline constexpr auto kSlfDirectionSpaceNames = common::enum_table<SlfDirectionSpace>(
    "direction space", {{SlfDirectionSpace::kView, "view"},
                        {SlfDirectionSpace::kReflected, "reflected"},
                        {SlfDirectionSpace::kLocal, "local"}});

struct SlfGrid {
  int azimuth = 32;    // Z
  int elevation = 16;  // W
  SlfDirectionSpace space = SlfDirectionSpace::kView;
  int directions() const { return azimuth * elevation; }
  void validate() const;  // both in [1, 4096]; std::invalid_argument naming the bad one
};

// Eq. 1: the unit direction at lat-long coordinates (xi1, xi2).
Eigen::Vector3d slf_direction(double xi1, double xi2);
// The same with the polar angle given by its cosine, cos(pi xi2): no acos and cos back for
// a caller that samples the cosine (a cell uniform in solid angle).
Eigen::Vector3d slf_direction_at_cosine(double xi1, double cos_polar);
// Eq. 2: (xi1, xi2) of a direction (need not be unit; zero gives (1, 0.5)).
Eigen::Vector2d slf_coordinates(const Eigen::Vector3d& direction);
// The centre of column j Z + i, in the grid's axes.
Eigen::Vector3d slf_grid_direction(const SlfGrid& grid, int column);

// Whether the grid's directions depend on each point's shading normal (every space but the
// view's), so that a renderer needs the normals.
bool slf_grid_uses_normals(const SlfGrid& grid);
// The polar angle the W rows span: pi over the sphere, pi / 2 over the local hemisphere.
double slf_polar_span(const SlfGrid& grid);

// The local grid's frame at a unit shading normal: columns the tangent t (azimuth 0), the
// bitangent t x n (a quarter turn of azimuth on, as Eq. 1's +X is from its -Z) and the
// normal n.
Eigen::Matrix3d slf_local_frame(const Eigen::Vector3d& normal);

// Where a unit view (from the point toward the viewer) sits on the grid, at a point of unit
// shading normal `normal`, as a unit direction in the grid's own axes (Eq. 1's, +Y the
// pole): the view itself, its reflection, or the view in the local frame.
Eigen::Vector3d slf_grid_space(const SlfGrid& grid, const Eigen::Vector3d& view,
                               const Eigen::Vector3d& normal);
// The inverse: the view a direction in the grid's axes stands for.
Eigen::Vector3d slf_grid_view(const SlfGrid& grid, const Eigen::Vector3d& grid_direction,
                              const Eigen::Vector3d& normal);
// The same two maps at one point, its local frame computed once: what the bake uses for the
// thousands of views it samples at each texel.
class SlfPointSpace {
 public:
  SlfPointSpace(const SlfGrid& grid, const Eigen::Vector3d& normal);
  Eigen::Vector3d to_grid(const Eigen::Vector3d& view) const;            // slf_grid_space
  Eigen::Vector3d to_view(const Eigen::Vector3d& grid_direction) const;  // slf_grid_view

 private:
  SlfDirectionSpace space_;
  Eigen::Vector3d normal_;
  Eigen::Matrix3d frame_;  // the local grid's only
};

// (xi1, xi2) of a direction in the grid's axes, xi2 over the grid's polar span (clamped to 1
// below the local grid's horizon).
Eigen::Vector2d slf_grid_coordinates(const SlfGrid& grid, const Eigen::Vector3d& grid_direction);

}  // namespace prt
