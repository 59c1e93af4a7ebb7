#include "render/camera.h"

#include "render/glm_eigen.h"

#include <glm/gtc/matrix_transform.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace render {

namespace {

double tan_half_fov(double fov_y_degrees) {
  return std::tan(0.5 * fov_y_degrees * std::numbers::pi / 180.0);
}

}  // namespace

void Camera::validate() const {
  if (width < 1 || height < 1 || width > 16384 || height > 16384)
    throw std::invalid_argument("--width/--height must be in 1..16384, got " +
                                std::to_string(width) + " x " + std::to_string(height));
  if (!(fov_y_degrees > 0.0 && fov_y_degrees < 180.0))
    throw std::invalid_argument("--fov must be in (0, 180) degrees, got " +
                                std::to_string(fov_y_degrees));
  const Eigen::Vector3d forward = target - eye;
  if (!(forward.norm() > 0.0) || !eye.allFinite() || !target.allFinite())
    throw std::invalid_argument("--eye and --target must be finite and different points");
  if (!(up.cross(forward.normalized()).norm() > 1e-6 * up.norm()))
    throw std::invalid_argument(
        "--up must not be parallel to the viewing direction --target - --eye");
  if (!(near_plane > 0.0 && far_plane > near_plane))
    throw std::invalid_argument("camera clip planes must satisfy 0 < near < far");
}

// GLM owns the GL conventions (right-handed, clip z in [-w, w]); Eigen keeps the interface
// the numerics use (render/glm_eigen.h).
Eigen::Matrix4d Camera::view_from_world() const {
  return to_eigen(glm::lookAt(to_glm(eye), to_glm(target), to_glm(up)));
}

Eigen::Matrix4d Camera::clip_from_view() const {
  return to_eigen(glm::perspective(glm::radians(fov_y_degrees), aspect(), near_plane, far_plane));
}

Eigen::Vector3d Camera::pixel_direction(double x, double y) const {
  const Eigen::Vector3d f = (target - eye).normalized();
  const Eigen::Vector3d r = f.cross(up).normalized();
  const Eigen::Vector3d u = r.cross(f);
  const double t = tan_half_fov(fov_y_degrees);
  const double ndc_x = 2.0 * (x + 0.5) / width - 1.0;
  const double ndc_y = 1.0 - 2.0 * (y + 0.5) / height;
  return (f + ndc_x * t * aspect() * r + ndc_y * t * u).normalized();
}

void fit_clip_planes(Camera& camera, const Eigen::Vector3d& center, double radius) {
  const double distance = (camera.eye - center).norm();
  const double margin = 1.05 * std::max(radius, 1e-12);
  camera.far_plane = distance + margin;
  // Inside the sphere nothing brackets it; keep a fixed depth range ratio instead.
  camera.near_plane = std::max(distance - margin, camera.far_plane * 1e-4);
}

Camera place_camera(const CameraPlacement& placement, const Eigen::Vector3d& center, double radius,
                    int width, int height) {
  Camera camera = frame_sphere(center, radius, width, height, placement.fov_y_degrees);
  if (placement.target) camera.target = *placement.target;
  if (placement.eye) camera.eye = *placement.eye;
  if (placement.up) camera.up = *placement.up;
  fit_clip_planes(camera, center, radius);
  camera.validate();
  return camera;
}

Camera frame_sphere(const Eigen::Vector3d& center, double radius, int width, int height,
                    double fov_y_degrees) {
  Camera c;
  c.width = width;
  c.height = height;
  c.fov_y_degrees = fov_y_degrees;
  const double t_y = tan_half_fov(fov_y_degrees);
  const double t_min = std::min(t_y, t_y * double(width) / double(height));
  // The sphere's silhouette fits a cone of half-angle atan(t_min) when sin(half) * d >= r.
  const double sin_half = t_min / std::sqrt(1.0 + t_min * t_min);
  const double r = radius > 0.0 ? radius : 1.0;
  const double distance = 1.05 * r / sin_half;
  c.target = center;
  c.eye = center + Eigen::Vector3d(0, 0, distance);
  c.up = Eigen::Vector3d::UnitY();
  fit_clip_planes(c, center, r);
  return c;
}

Camera rotated(const Camera& camera, const Eigen::Matrix3d& rotation,
               const Eigen::Vector3d& pivot) {
  Camera c = camera;
  c.eye = pivot + rotation * (camera.eye - pivot);
  c.target = pivot + rotation * (camera.target - pivot);
  c.up = rotation * camera.up;
  return c;
}

}  // namespace render
