// apps/prtr/view_flags.h: the camera, image and environment-rotation flags shared by the
// commands that render (relight, render, overdraw): --width --height --eye --target --up
// --fov --background --exposure --axis.
#pragma once

#include "meshes/mesh.h"
#include "render/camera.h"
#include "render/renderer.h"

#include <CLI/CLI.hpp>

#include <string>

namespace prtr_app {

struct ViewFlags {
  int width = 1280, height = 948;  // the thesis's resolution
  double fov = 40.0, exposure = 0.0;
  std::string eye, target, up, background = "probe", axis = "0,1,0";
};

void add_view_flags(CLI::App* command, ViewFlags& flags);

// "x,y,z" -> vector; UsageError naming the flag otherwise.
Eigen::Vector3d parse_vector(const std::string& text, const char* flag);

// --eye/--target/--up/--fov as a placement (UsageError naming a malformed flag).
render::CameraPlacement resolve_placement(const ViewFlags& flags);
// The default camera frames the mesh's bounding sphere; --eye/--target/--up override it.
render::Camera resolve_camera(const ViewFlags& flags, const meshes::Mesh& mesh);
render::Background resolve_background(const ViewFlags& flags);
// The unit environment-rotation axis (relight --camera-orbit: the camera's orbit axis).
Eigen::Vector3d resolve_axis(const ViewFlags& flags);

// The point the default camera looks at: the centre of the mesh's bounding box.
Eigen::Vector3d mesh_centre(const meshes::Mesh& mesh);
// `camera` turned by `radians` about the unit `axis` through `centre` (right-handed:
// counter-clockwise seen from the axis's tip): eye, target and up turn together, so the
// view of the mesh turns and nothing else about the camera changes.
render::Camera orbit_camera(const render::Camera& camera, const Eigen::Vector3d& centre,
                            const Eigen::Vector3d& axis, double radians);

}  // namespace prtr_app
