#include "view_flags.h"

#include "commands.h"
#include "flag_checks.h"

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

namespace prtr_app {

void add_view_flags(CLI::App* cmd, ViewFlags& f) {
  add_checked_option(cmd, "--width", f.width, "Image width", integer_in(1, 16384));
  add_checked_option(cmd, "--height", f.height, "Image height", integer_in(1, 16384));
  cmd->add_option("--eye", f.eye, "Camera position x,y,z (default: frames the bounding sphere)");
  cmd->add_option("--target", f.target, "Camera target x,y,z (default: the sphere's centre)");
  cmd->add_option("--up", f.up, "Camera up x,y,z (default: 0,1,0)");
  // Open at both ends; the camera refuses 0 and 180 by name.
  add_checked_option(cmd, "--fov", f.fov, "Vertical field of view (degrees)", number_in(0, 180));
  cmd->add_option("--background", f.background, "probe, black, or a colour R,G,B")
      ->capture_default_str();
  // 2^64 times a radiance of 1e20 is still a float; past it the PNG would be all Inf.
  add_checked_option(cmd, "--exposure", f.exposure, "PNG exposure in stops", number_in(-64, 64));
  cmd->add_option("--axis", f.axis,
                  "Environment rotation axis x,y,z (relight --camera-orbit: the camera's orbit "
                  "axis, through the mesh's centre)")
      ->capture_default_str();
}

Eigen::Vector3d parse_vector(const std::string& text, const char* flag) {
  const auto parsed = parse_number_list(text);
  if (!parsed) throw UsageError(std::string(flag) + ": '" + text + "' is not a list of numbers");
  const std::vector<double>& values = *parsed;
  if (values.size() != 3)
    throw UsageError(std::string(flag) + " takes 3 comma-separated numbers x,y,z, got '" + text +
                     "'");
  // std::stod reads "nan" and "inf"; a non-finite eye, axis or colour poisons every pixel.
  // Float range too: a colour of 1e300 is infinite once the renderer narrows it.
  for (double v : values) {
    if (!std::isfinite(v) || std::abs(v) > 1e30)
      throw UsageError(std::string(flag) + ": '" + text +
                       "' has a value that is not a finite number of at most 1e30");
  }
  return {values[0], values[1], values[2]};
}

render::CameraPlacement resolve_placement(const ViewFlags& f) {
  render::CameraPlacement placement;
  placement.fov_y_degrees = f.fov;
  if (!f.target.empty()) placement.target = parse_vector(f.target, "--target");
  if (!f.eye.empty()) placement.eye = parse_vector(f.eye, "--eye");
  if (!f.up.empty()) placement.up = parse_vector(f.up, "--up");
  return placement;
}

Eigen::Vector3d mesh_centre(const meshes::Mesh& mesh) {
  return meshes::bounds(mesh).center().cast<double>();
}

render::Camera orbit_camera(const render::Camera& camera, const Eigen::Vector3d& centre,
                            const Eigen::Vector3d& axis, double radians) {
  // Unturned exactly: centre + (eye - centre) need not round back to eye.
  if (radians == 0.0) return camera;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(radians, axis).toRotationMatrix();
  render::Camera turned = camera;
  turned.eye = centre + r * (camera.eye - centre);
  turned.target = centre + r * (camera.target - centre);
  turned.up = r * camera.up;
  return turned;
}

render::Camera resolve_camera(const ViewFlags& f, const meshes::Mesh& mesh) {
  const render::CameraPlacement placement = resolve_placement(f);
  const Eigen::Vector3d centre = mesh_centre(mesh);
  double radius = 0.0;
  for (const auto& p : mesh.positions)
    radius = std::max(radius, (p.cast<double>() - centre).norm());
  try {
    return render::place_camera(placement, centre, radius, f.width, f.height);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

render::Background resolve_background(const ViewFlags& f) {
  render::Background background;
  if (f.background == "probe") {
    background.use_probe = true;
  } else if (f.background == "black") {
    background.use_probe = false;
  } else {
    background.use_probe = false;
    background.colour = parse_vector(f.background, "--background").cast<float>();
  }
  return background;
}

Eigen::Vector3d resolve_axis(const ViewFlags& f) {
  const Eigen::Vector3d axis = parse_vector(f.axis, "--axis");
  if (!(axis.norm() > 0)) throw UsageError("--axis must not be the zero vector");
  return axis.normalized();
}

}  // namespace prtr_app
