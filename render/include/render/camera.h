// render/camera.h: a pinhole camera and its matrices (column vectors, OpenGL clip space).
//
// Conventions: right-handed world, +Y up (meshes/mesh.h). The camera looks from `eye` toward
// `target`; `fov_y_degrees` is the full vertical field of view; pixel rows run top to bottom
// in images (render/image.h) although GL's framebuffer rows run bottom to top.
// Matrices are named destination-from-source: clip_from_world = clip_from_view * view_from_world.
#pragma once

#include <Eigen/Core>

#include <optional>

namespace render {

struct Camera {
  Eigen::Vector3d eye = Eigen::Vector3d(0, 0, 3);
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();
  double fov_y_degrees = 40.0;
  int width = 1280, height = 948;  // the thesis's resolution
  double near_plane = 0.1, far_plane = 100.0;

  double aspect() const { return double(width) / double(height); }
  // Throws std::invalid_argument naming the field (as its CLI flag) when the camera cannot
  // make an image: non-positive size, fov outside (0, 180), eye == target, up parallel to
  // the viewing direction, near/far not 0 < near < far.
  void validate() const;

  Eigen::Matrix4d view_from_world() const;
  Eigen::Matrix4d clip_from_view() const;
  Eigen::Matrix4d clip_from_world() const { return clip_from_view() * view_from_world(); }
  // Unit world direction through the centre of pixel (x, y), row 0 at the top; fractional
  // (x, y) move off the centre, so pixel (x, y) spans x - 0.5 .. x + 0.5.
  Eigen::Vector3d pixel_direction(double x, double y) const;
  // Through sample (i, j) of an n x n grid over pixel (x, y), each at the centre of its
  // sub-pixel: the positions an n-times supersampled frame (render/supersample.h) shades.
  Eigen::Vector3d subpixel_direction(int x, int y, int i, int j, int n) const {
    return pixel_direction(x - 0.5 + (i + 0.5) / n, y - 0.5 + (j + 0.5) / n);
  }
};

// The default camera: looks down -Z (probe centre behind the object, probes/probe.h) at the
// bounding sphere (centre, radius) so that the whole sphere fits the narrower field of view
// with a small margin; near and far planes bracket the sphere.
Camera frame_sphere(const Eigen::Vector3d& center, double radius, int width, int height,
                    double fov_y_degrees = 40.0);

// Where a viewer wants the camera: the framed bounding sphere unless an eye, target or up is
// given (each replaces the framed one).
struct CameraPlacement {
  std::optional<Eigen::Vector3d> eye, target, up;
  double fov_y_degrees = 40.0;
};

// The camera `placement` asks for at width x height around the bounding sphere (center,
// radius), clip planes fitted to the sphere; validated (std::invalid_argument, see validate).
Camera place_camera(const CameraPlacement& placement, const Eigen::Vector3d& center, double radius,
                    int width, int height);

// Sets near/far so that they bracket the sphere as seen from camera.eye (keeps the rest).
void fit_clip_planes(Camera& camera, const Eigen::Vector3d& center, double radius);

// The same camera moved rigidly by the rotation R about `pivot` (eye, target and up).
Camera rotated(const Camera& camera, const Eigen::Matrix3d& rotation,
               const Eigen::Vector3d& pivot = Eigen::Vector3d::Zero());

}  // namespace render
