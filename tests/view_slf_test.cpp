// prtr view's surface light field scene (viewer/slf_scene.h): a frame for a state's camera is
// the CPU reference's image (render/slf_reference.h) from the camera worked out by hand for
// that orbit and zoom, supersampled frames are the filtered larger reference, and every state
// a baked light field cannot show is refused with its reason, naming the parameter first.
#include "viewer/server.h"
#include "viewer/slf_scene.h"

#include "meshes/atlas.h"
#include "meshes/procedural.h"
#include "pipeline/slf.h"
#include "probes/procedural.h"
#include "render/slf_from_compressed.h"
#include "render/slf_reference.h"
#include "render/supersample.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace {

using Eigen::Vector3d;
using viewer::ViewState;

// A small sphere baked under light from one side (so that turning the camera changes what it
// sees) and compressed, in about a second.
struct Baked {
  meshes::Mesh mesh = meshes::make_sphere(1.f, 12, 6);
  probes::Probe probe = probes::make_from_function(32, 16, [](const Vector3d& d) {
    return probes::Rgb(float(1.2 + d.x()), float(1.0 + 0.5 * d.y()), float(0.6 + 0.4 * d.z()));
  });
  render::SlfModel model;

  Baked() {
    pipeline::SlfSettings s;
    s.atlas_width = s.atlas_height = 32;
    s.bake.grid = {8, 4};
    s.bake.spp = 2;
    s.bake.material.kind = prt::MaterialKind::kPhong;
    s.bake.material.exponent = 8.f;
    s.compress.clusters = 4;
    s.compress.components = 3;
    const pipeline::SlfRun run = pipeline::make_slf(mesh, "sphere.obj", probe, "p", s, {}, {});
    const meshes::Atlas atlas = meshes::make_atlas(mesh, s.atlas_width, s.atlas_height);
    model = render::slf_model_from_compressed(mesh, atlas, s.bake.grid, run.slf.set);
  }
};

const Baked& baked() {
  static const Baked b;
  return b;
}

const Eigen::Vector3f kBackground(0.1f, 0.2f, 0.3f);

viewer::SlfSceneInputs inputs(render::SlfShading shading) {
  viewer::SlfSceneInputs in;
  in.shading = shading;
  in.mesh = &baked().mesh;
  in.model = &baked().model;
  in.probe = &baked().probe;
  in.name = "sphere.slfc";
  in.camera.eye = Vector3d(0, 0, 4);
  in.camera.target = Vector3d::Zero();
  in.background.use_probe = false;
  in.background.colour = kBackground;
  return in;
}

// Pixels whose alpha or (relative to the image's brightest radiance) colour differ by more
// than `tolerance`. GL's rasterisation and the ray cast may put a pixel centre within
// rounding of an edge on different triangles, so a few differ along the silhouette and the
// triangles' edges (the atlas gives every triangle its own texels); render/slf_renderer.h holds
// the rest to float rounding.
int differing(const render::Image& gl, const render::Image& cpu, double tolerance) {
  EXPECT_EQ(gl.width, cpu.width);
  EXPECT_EQ(gl.height, cpu.height);
  if (gl.width != cpu.width || gl.height != cpu.height) return gl.width * gl.height;
  double scale = 0;
  for (std::size_t i = 0; i < cpu.rgba.size(); ++i)
    if (i % 4 != 3) scale = std::max(scale, double(std::abs(cpu.rgba[i])));
  int count = 0;
  for (int y = 0; y < cpu.height; ++y)
    for (int x = 0; x < cpu.width; ++x) {
      const float* a = gl.pixel(x, y);
      const float* b = cpu.pixel(x, y);
      double e = a[3] != b[3] ? 1.0 : 0.0;
      for (int c = 0; c < 3; ++c) e = std::max(e, std::abs(double(a[c]) - b[c]) / scale);
      count += e > tolerance;
    }
  return count;
}

int covered(const render::Image& image) {
  int n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) n += image.pixel(x, y)[3] == 1.f;
  return n;
}

constexpr double kTolerance = 1e-4;  // render/slf_renderer.h against its reference
constexpr int kEdgePixels = 24;

// Placement eye (0, 0, 4) looking at the origin; cam_yaw turns it about +Y (right-handed) and
// zoom divides its distance: yaw 90 and zoom 1.25 put it at (3.2, 0, 0).
// Texture space here (the reference with each texel's own direction), one pass below.
TEST(ViewSlfScene, FrameIsTheReferenceFromTheOrbitedCamera) {
  viewer::SlfScene scene(inputs(render::SlfShading::kTextureSpace));
  ViewState s;
  s.width = 64;
  s.height = 48;
  s.cam_yaw = 90;
  s.zoom = 1.25;
  const auto frame = scene.render(s);
  ASSERT_EQ(frame->request_error, "");
  ASSERT_EQ(frame->server_error, "");
  render::Camera expected;
  expected.eye = Vector3d(3.2, 0, 0);
  expected.width = 64;
  expected.height = 48;
  expected.near_plane = 0.5;
  expected.far_plane = 10;
  const render::Image cpu =
      render::render_slf_reference(baked().model, expected, {true, kBackground, true});
  EXPECT_GT(covered(cpu), 64 * 48 / 4);
  EXPECT_LE(differing(frame->image, cpu, kTolerance), kEdgePixels);
  EXPECT_EQ(frame->stats.passes, 1);
  EXPECT_EQ(viewer::frame_header(*frame).at("kind"), "slf");  // the page's and X-Prtr-Frame's
  EXPECT_EQ(frame->stats.clusters, 4);
  EXPECT_EQ(frame->stats.pcs, 3);

  // The unorbited view is another image (the light comes from +X), and the reference's too.
  s.cam_yaw = 0;
  const auto front = scene.render(s);
  ASSERT_EQ(front->request_error, "");
  EXPECT_GT(differing(front->image, cpu, kTolerance), 64 * 48 / 8);
  expected.eye = Vector3d(0, 0, 3.2);
  EXPECT_LE(
      differing(front->image,
                render::render_slf_reference(baked().model, expected, {true, kBackground, true}),
                kTolerance),
      kEdgePixels);
}

// cam_pitch turns the eye about the camera's right axis (+X here) toward -Y, up with it.
TEST(ViewSlfScene, PitchedAndSupersampledFrameIsTheFilteredLargeReference) {
  viewer::SlfScene scene(inputs(render::SlfShading::kOnePass));
  ViewState s;
  s.width = 40;
  s.height = 30;
  s.cam_pitch = 30;
  s.samples = 2;
  s.exposure = 3;  // applied when the frame is encoded, not to the linear image
  const auto frame = scene.render(s);
  ASSERT_EQ(frame->request_error, "");
  render::Camera expected;
  const double a = 30 * std::acos(-1.0) / 180;
  expected.eye = Vector3d(0, -4 * std::sin(a), 4 * std::cos(a));
  expected.up = Vector3d(0, std::cos(a), std::sin(a));
  expected.width = 40;
  expected.height = 30;
  expected.near_plane = 0.5;
  expected.far_plane = 10;
  const render::Image cpu = render::box_downsample(
      render::render_slf_reference(baked().model, render::supersampled(expected, 2),
                                   {true, kBackground}),
      2);
  ASSERT_EQ(frame->image.width, 40);
  EXPECT_LE(differing(frame->image, cpu, kTolerance), kEdgePixels);
}

TEST(ViewSlfScene, WhatTheBakedLightingCannotShowIsRefusedWithItsReason) {
  using Change = std::function<void(ViewState&)>;
  const std::vector<std::pair<Change, std::string>> cases = {
      {[](ViewState& s) { s.env_yaw = 10; },
       "env_yaw=10: the lighting is baked into sphere.slfc; orbit the camera instead"},
      {[](ViewState& s) { s.env_pitch = -2.5; },
       "env_pitch=-2.5: the lighting is baked into sphere.slfc; orbit the camera instead"},
      {[](ViewState& s) { s.probe = 1; }, "probe=1: sphere.slfc shows only the probe"},
      {[](ViewState& s) { s.overlay = viewer::Overlay::kClusters; }, "overlay=clusters: "},
      {[](ViewState& s) { s.overlay = viewer::Overlay::kOverdraw; }, "overlay=overdraw: "},
      {[](ViewState& s) { s.clusters = 8; }, "clusters=8: sphere.slfc holds one compression"},
      {[](ViewState& s) { s.pcs = 2; }, "pcs=2: "},
      {[](ViewState& s) { s.order = 3; }, "order=3: "},
      {[](ViewState& s) { s.mode = render::Mode::kMultipass; }, "mode=multipass: "},
      {[](ViewState& s) { s.strategy = "order"; }, "strategy=order: "},
      {[](ViewState& s) { s.register_budget = 256; }, "budget=256: "},
      {[](ViewState& s) { s.clusters_per_pass = 1; }, "cpp=1: "},
  };
  viewer::SlfScene scene(inputs(render::SlfShading::kAutomatic));
  for (const auto& [change, reason] : cases) {
    ViewState s;
    s.width = s.height = 16;
    change(s);
    try {
      viewer::check_slf_request(s, "sphere.slfc");
      ADD_FAILURE() << "accepted a state that should give: " << reason;
    } catch (const viewer::RequestError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(reason, 0), 0u) << e.what();
    }
    const auto frame = scene.render(s);
    EXPECT_EQ(frame->request_error.rfind(reason, 0), 0u) << frame->request_error;
    EXPECT_EQ(frame->request_error.find('\n'), std::string::npos);
    EXPECT_TRUE(frame->image.rgba.empty());
  }
  // The camera, size, exposure and samples are what it can change.
  ViewState s;
  s.width = s.height = 16;
  s.cam_yaw = -120;
  s.cam_pitch = 80;
  s.zoom = 3;
  s.exposure = -2;
  s.samples = 3;
  EXPECT_NO_THROW(viewer::check_slf_request(s, "sphere.slfc"));
  const auto frame = scene.render(s);
  EXPECT_EQ(frame->request_error, "");
  EXPECT_EQ(frame->image.width, 16);
}

}  // namespace
