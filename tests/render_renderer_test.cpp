// The renderer's modes against the CPU reference and against each other, on small baked
// meshes and small images. The oracles: render/shading.h's reference (reconstruct each
// vertex in double, evaluate prt::sh_eval), cpca::overdraw for the triangle counts, Probe's
// own lookup for the background, and the rotation symmetry of an unoccluded sphere.
#include "render/renderer.h"

#include "cpca/supercluster.h"
#include "meshes/procedural.h"
#include "probes/load.h"
#include "probes/procedural.h"
#include "prt/bake.h"
#include "prt/sh_rotation.h"
#include "render/floor_harness.h"
#include "render/gl_context.h"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include "gl_api.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace {

// GL float sums of ~300 products against double: rounding stays near 1e-6 of the largest
// radiance; 1e-4 leaves room for llvmpipe's fused multiply-adds.
constexpr double kVertexTolerance = 1e-4;
// Passes add the same products in another order: float rounding only. A pixel sums
// L = (components + 1) * order^2 products per channel (mean and PCs against the projected
// lighting); two summation orders of L float terms differ by at most 2 (L - 1) u sum|term|,
// u = 2^-24. The glossy products alternate in sign, so sum|term| is allowed to reach 4 times
// the brightest pixel. Relative to that pixel this is 1.2e-5 for order 3 with 2 PCs and
// 5.9e-5 for order 5 with 4; a misplaced cluster or pass errs by 1e-2 or more. (Compilers
// differ in contracting multiply-adds, which moves the sum within this bound: under the
// sanitizer build order 4 with 4 PCs measured 1.2e-5, against 3.8e-5 here.)
double image_tolerance(int order, int components) {
  const double terms = double(components + 1) * order * order;
  return 2.0 * (terms - 1.0) * 0x1p-24 * 4.0;
}

prt::TransferSet bake_small(const meshes::Mesh& mesh, int order, prt::TransferKind kind,
                            bool coloured = false) {
  prt::BakeOptions o;
  o.kind = kind;
  o.order = order;
  o.samples = 96;
  o.bounces = 0;
  o.material.kind = prt::MaterialKind::kPhong;
  o.material.exponent = 8.f;
  if (coloured) o.material.albedo = Eigen::Vector3f(0.5f, 0.3f, 0.1f);
  return prt::bake(mesh, o);
}

// Clusters of `group` consecutive vertices, each fitted by exact PCA (Eigen's solver) with
// `components` PCs: lossless when components >= group - 1, lossy below; coarser groups and
// fewer PCs lose more. A hand-built stand-in for cpca::compress with a known ordering.
cpca::CompressedSet compress_by_groups(const prt::TransferSet& t, int group, int components) {
  cpca::CompressedSet s;
  s.order = t.order;
  s.channels = t.channels;
  s.columns = t.columns();
  s.vertex_count = t.vertex_count;
  s.component_count = components;
  const std::size_t D = t.floats_per_vertex();
  const int V = int(t.vertex_count);
  s.cluster_count = (V + group - 1) / group;
  s.cluster_of.resize(std::size_t(V));
  s.weights.assign(std::size_t(V) * components, 0.f);
  s.means.assign(std::size_t(s.cluster_count) * D, 0.f);
  s.bases.assign(std::size_t(s.cluster_count) * components * D, 0.f);
  for (int k = 0; k < s.cluster_count; ++k) {
    const int first = k * group, m = std::min(group, V - first);
    Eigen::MatrixXd x(m, Eigen::Index(D));
    for (int i = 0; i < m; ++i) {
      s.cluster_of[std::size_t(first + i)] = std::uint32_t(k);
      for (std::size_t d = 0; d < D; ++d) x(i, Eigen::Index(d)) = t.data[(first + i) * D + d];
    }
    const Eigen::RowVectorXd mean = x.colwise().mean();
    const Eigen::MatrixXd centred = x.rowwise() - mean;
    for (std::size_t d = 0; d < D; ++d) s.means[k * D + d] = float(mean[Eigen::Index(d)]);
    const int used = std::min(components, m);
    if (used == 0) continue;
    // Gram-matrix PCA (m << D): eigenvectors u of C C^T give directions C^T u / sigma.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(centred * centred.transpose());
    Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(used, Eigen::Index(D));
    for (int j = 0; j < used; ++j) {
      const double lambda = eig.eigenvalues()[m - 1 - j];  // ascending order
      if (lambda > 1e-20 * std::max(1.0, eig.eigenvalues()[m - 1]))
        basis.row(j) = (centred.transpose() * eig.eigenvectors().col(m - 1 - j)).transpose() /
                       std::sqrt(lambda);
    }
    const Eigen::MatrixXd w = centred * basis.transpose();
    for (int j = 0; j < used; ++j)
      for (std::size_t d = 0; d < D; ++d)
        s.bases[(std::size_t(k) * components + j) * D + d] = float(basis(j, Eigen::Index(d)));
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < used; ++j)
        s.weights[std::size_t(first + i) * components + j] = float(w(i, j));
  }
  cpca::validate(s);
  return s;
}

// A smooth, coloured, clearly directional environment.
probes::Probe test_probe() {
  return probes::make_from_function(64, 32, [](const Eigen::Vector3d& d) {
    const double sun =
        std::pow(std::max(0.0, d.dot(Eigen::Vector3d(0.3, 0.8, 0.5).normalized())), 8);
    return probes::Rgb(float(0.2 + 2.0 * sun + 0.3 * std::max(0.0, d.x())), float(0.25 + 1.5 * sun),
                       float(0.3 + sun + 0.4 * std::max(0.0, -d.z())));
  });
}

struct Scene {
  meshes::Mesh mesh;
  prt::TransferSet transfer;
  cpca::CompressedSet set;
  probes::Probe probe;
  prt::ShLighting lighting;
  render::Camera camera;
};

Scene make_scene(const meshes::Mesh& mesh, int order, int group, int components,
                 prt::TransferKind kind = prt::TransferKind::kGlossy, bool coloured = false) {
  Scene s;
  s.mesh = mesh;
  s.transfer = bake_small(mesh, order, kind, coloured);
  s.set = compress_by_groups(s.transfer, group, components);
  s.probe = test_probe();
  s.lighting = prt::project(s.probe, order);
  const meshes::Bounds b = meshes::bounds(mesh);
  s.camera = render::frame_sphere(b.center().cast<double>(), 0.5 * b.diagonal(), 64, 48);
  s.camera.eye = s.camera.target + (s.camera.eye - s.camera.target).norm() *
                                       Eigen::Vector3d(0.3, 0.5, 1.0).normalized();
  render::fit_clip_planes(s.camera, s.camera.target, 0.5 * b.diagonal());
  return s;
}

Eigen::Matrix3d test_rotation() {
  return prt::axis_angle(Eigen::Vector3d(1, 2, 3).normalized(), 0.7);
}

render::RendererOptions options(render::Mode mode, int budget = 0) {
  render::RendererOptions o;
  o.mode = mode;
  o.register_budget = budget;
  return o;
}

double max_relative_error(const std::vector<render::Rgb>& a, const std::vector<render::Rgb>& ref) {
  double scale = 0.0, worst = 0.0;
  for (const auto& r : ref) scale = std::max(scale, double(r.cwiseAbs().maxCoeff()));
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, double((a[i] - ref[i]).cwiseAbs().maxCoeff()));
  return worst / scale;
}

double max_abs_difference(const render::Image& a, const render::Image& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.rgba.size(); ++i)
    worst = std::max(worst, double(std::abs(a.rgba[i] - b.rgba[i])));
  return worst;
}

render::Image render_once(render::GlContext&, const Scene& s, const render::RendererOptions& o,
                          const render::Camera& camera, const Eigen::Matrix3d& rotation,
                          render::RenderStats* stats = nullptr) {
  render::Renderer r(s.mesh, &s.set, &s.transfer, &s.probe, o);
  r.render(camera, s.lighting, rotation);
  if (stats) *stats = r.stats();
  return r.read_image();
}

// --- Transform feedback capture against the CPU reference --------------------------------

struct CaptureCase {
  int order;
  prt::TransferKind kind;
  bool coloured;
};

class CaptureTest : public ::testing::TestWithParam<CaptureCase> {};

TEST_P(CaptureTest, EveryModeMatchesTheCpuReference) {
  const CaptureCase c = GetParam();
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 6, 0.5f, 1.0f, 12, 6), c.order, 8,
                             3, c.kind, c.coloured);
  const Eigen::Matrix3d R = test_rotation();
  const prt::ShLighting lit = prt::ShRotation(c.order, R).apply(s.lighting);
  const auto reference = render::reference_vertex_radiance(s.set, s.mesh, lit, s.camera.eye);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  for (render::Mode mode : {render::Mode::kMultipass, render::Mode::kSinglepass,
                            render::Mode::kDecoupled, render::Mode::kCpu})
    for (bool feedback : {true, false})
      for (render::Constants constants : {render::Constants::kCpu, render::Constants::kGpu}) {
        if (!feedback && mode != render::Mode::kMultipass) continue;
        // Three clusters per pass: several passes, so the sum over passes is exercised.
        render::RendererOptions o = options(mode, 3 * registers);
        o.multipass_feedback = feedback;
        o.constants = constants;
        render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, o);
        const auto captured = r.capture_vertex_radiance(s.camera, s.lighting, R);
        const std::string label = std::string(render::kModeNames.name(mode)) +
                                  (feedback ? "" : ", in-draw shading") + ", constants on the " +
                                  render::kConstantsNames.name(constants);
        EXPECT_LT(max_relative_error(captured, reference), kVertexTolerance) << label;
        // The CPU-shaded path needs the constants on the host whatever was asked.
        EXPECT_EQ(r.stats().constants,
                  mode == render::Mode::kCpu ? render::Constants::kCpu : constants)
            << label;
      }
}

// The warm-up frames last at least warmup_ms (a GPU left idle by a long set-up needs them to
// reach its clocks), and the timed frames follow them.
TEST(Renderer, WarmUpLastsAtLeastItsMilliseconds) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_sphere(1.f, 10, 5), 3, 10, 2);
  render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, options(render::Mode::kSinglepass));
  const auto start = std::chrono::steady_clock::now();
  const render::TimingSummary t = render::measure(r, s.camera, s.lighting, test_rotation(),
                                                  Eigen::Vector3d::UnitY(), 1.0, 2, 1, 250.0);
  const double elapsed =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(elapsed, 250.0);
  EXPECT_EQ(t.frames, 2);
  EXPECT_GT(t.frame_ms_median, 0.0);
}

// The compute dispatch reruns every frame: after one rotation and then another, the image is
// the CPU constants' image of the second, and differs from the first's.
TEST(Renderer, GpuConstantsFollowTheLightingFrameByFrame) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 4, 10, 3);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  const Eigen::Matrix3d first = test_rotation();
  const Eigen::Matrix3d second = prt::axis_angle(Eigen::Vector3d(0, 1, 0), 2.1) * first;
  for (render::Mode mode :
       {render::Mode::kMultipass, render::Mode::kSinglepass, render::Mode::kDecoupled}) {
    render::RendererOptions o = options(mode, 3 * registers);
    render::RenderStats stats;
    const render::Image cpu = render_once(ctx, s, o, s.camera, second, &stats);
    EXPECT_EQ(stats.constants, render::Constants::kCpu) << "kAuto on llvmpipe";
    o.constants = render::Constants::kGpu;
    render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, o);
    r.render(s.camera, s.lighting, first);
    const render::Image before = r.read_image();
    r.render(s.camera, s.lighting, second);
    const render::Image after = r.read_image();
    const double peak = cpu.max_rgb();
    ASSERT_GT(peak, 0.0);
    EXPECT_LE(max_abs_difference(after, cpu) / peak, 1e-5) << render::kModeNames.name(mode);
    EXPECT_GT(max_abs_difference(before, cpu) / peak, 1e-2) << render::kModeNames.name(mode);
  }
}

// Named "glossy_order3_grey" etc., so CTest lists the case rather than the parameter's bytes.
INSTANTIATE_TEST_SUITE_P(Orders, CaptureTest,
                         ::testing::Values(CaptureCase{3, prt::TransferKind::kGlossy, false},
                                           CaptureCase{6, prt::TransferKind::kGlossy, true},
                                           CaptureCase{4, prt::TransferKind::kDiffuse, false}),
                         [](const ::testing::TestParamInfo<CaptureCase>& p) {
                           return std::string(prt::kTransferKindNames.name(p.param.kind)) +
                                  "_order" + std::to_string(p.param.order) +
                                  (p.param.coloured ? "_rgb" : "_grey");
                         });

TEST(Renderer, UncompressedCaptureMatchesLosslessReference) {
  render::GlContext ctx;
  // Groups of 4 with 3 PCs reconstruct every vertex exactly (up to float rounding).
  const Scene s = make_scene(meshes::make_sphere(1.f, 10, 5), 4, 4, 3);
  const Eigen::Matrix3d R = test_rotation();
  const prt::ShLighting lit = prt::ShRotation(4, R).apply(s.lighting);
  const auto reference = render::reference_vertex_radiance(s.set, s.mesh, lit, s.camera.eye);
  render::Renderer r(s.mesh, nullptr, &s.transfer, &s.probe, options(render::Mode::kUncompressed));
  EXPECT_LT(max_relative_error(r.capture_vertex_radiance(s.camera, s.lighting, R), reference),
            kVertexTolerance);
}

// --- Generated shaders at every order -------------------------------------------------------

// A random compressed set on `mesh` (values in [-0.5, 0.5]): the shader only has to compute
// what the CPU reference computes from the same numbers, so no bake is needed.
cpca::CompressedSet random_set(const meshes::Mesh& mesh, int order, bool glossy, int channels) {
  cpca::CompressedSet s;
  s.order = order;
  s.channels = channels;
  s.columns = glossy ? order * order : 1;
  s.vertex_count = mesh.vertex_count();
  s.cluster_count = 3;
  // Below the dimension (order 1 glossy grey has a single number: no components).
  s.component_count = std::min<int>(2, int(s.dimension()) - 1);
  std::mt19937 rng(std::uint32_t(order * 7 + glossy));
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    s.cluster_of.push_back(std::uint32_t(v % 3));
  s.weights.resize(mesh.vertex_count() * std::size_t(s.component_count));
  s.means.resize(std::size_t(s.cluster_count) * s.dimension());
  s.bases.resize(std::size_t(s.cluster_count) * s.component_count * s.dimension());
  for (std::vector<float>* v : {&s.weights, &s.means, &s.bases})
    for (float& x : *v) x = u(rng);
  return s;
}

TEST(ShaderSource, CompiledShadersMatchTheCpuReferenceAtOrders1To10) {
  // Every order the engine accepts, glossy and diffuse: the generated SH basis and CPCA sums
  // (render/shader_source.h) compile, and the vertex stage's radiance equals the double
  // precision reference (render::reference_vertex_radiance, prt::sh_eval) through the
  // storage-buffer shader (single pass) and the literal-offset one (decoupled).
  render::GlContext ctx;
  meshes::Mesh mesh = meshes::make_sphere(1.f, 8, 4);
  const render::Camera camera = render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 32, 24);
  const Eigen::Matrix3d R = test_rotation();
  for (int order = 1; order <= 10; ++order) {
    std::mt19937 rng{std::uint32_t(order)};
    std::normal_distribution<double> n(0.0, 1.0);
    prt::ShLighting lighting(order * order, 3);
    for (Eigen::Index i = 0; i < lighting.size(); ++i) lighting.data()[i] = n(rng) / (1 + i / 3);
    const prt::ShLighting lit = prt::ShRotation(order, R).apply(lighting);
    for (bool glossy : {true, false}) {
      const cpca::CompressedSet set = random_set(mesh, order, glossy, glossy ? 1 : 3);
      const auto reference = render::reference_vertex_radiance(set, mesh, lit, camera.eye);
      for (render::Mode mode : {render::Mode::kSinglepass, render::Mode::kDecoupled}) {
        // Large glossy literal-offset shaders take llvmpipe seconds each to compile; their
        // code differs from the small ones only in the count of terms.
        if (mode == render::Mode::kDecoupled && glossy && order > 4) continue;
        render::Renderer r(mesh, &set, nullptr, nullptr, options(mode));
        EXPECT_LT(max_relative_error(r.capture_vertex_radiance(camera, lighting, R), reference),
                  kVertexTolerance)
            << "order " << order << (glossy ? " glossy " : " diffuse ")
            << render::kModeNames.name(mode);
      }
    }
  }
}

// --- The floor harness ---------------------------------------------------------------------

TEST(FloorHarness, MedianFrameIsPositiveAndBoundedByTheWallClock) {
  // The median of F frames is at most 2 x (wall time / F): at least half the frames take as
  // long as the median. And a frame that draws anything takes some time.
  render::GlContext ctx;
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 32, 16);
  const render::Camera camera = render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 128, 96);
  render::FloorOptions o;
  o.frames = 6;
  o.warmup = 0;
  const auto start = std::chrono::steady_clock::now();
  const double median = render::floor_frame_ms(mesh, camera, o);
  const double wall =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GT(median, 0.0);
  EXPECT_LE(median, 2.0 * wall / o.frames);
  o.cull_back_faces = false;
  o.optimize_vertex_cache = false;
  EXPECT_GT(render::floor_frame_ms(mesh, camera, o), 0.0);
}

TEST(FloorHarness, EveryFrameDrawsTheMeshUnderTheBackground) {
  // The background pass leaves depth writes off; a harness that cleared depth without
  // turning them back on kept frame 1's depth, so from frame 2 on the mesh failed GL_LESS
  // and only the background was drawn (and timed). The last of three frames must still show
  // the mesh's constant grey (0.5, alpha 1) at the centre and the probe at a corner.
  render::GlContext ctx;
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 32, 16);
  const render::Camera camera = render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 64, 48);
  const probes::Probe probe = probes::make_from_function(
      16, 8, [](const Eigen::Vector3d&) { return probes::Rgb(0.25f, 0.125f, 1.f); });
  render::Image last;
  render::FloorOptions o;
  o.frames = 3;
  o.warmup = 0;
  o.background = &probe;
  o.last_frame = &last;
  render::floor_frame_ms(mesh, camera, o);
  ASSERT_EQ(last.width, 64);
  const float* centre = last.pixel(32, 24);
  EXPECT_FLOAT_EQ(centre[0], 0.5f);
  EXPECT_FLOAT_EQ(centre[3], 1.f);
  const float* corner = last.pixel(0, 0);
  EXPECT_NEAR(corner[2], 1.f, 1e-5);
  EXPECT_FLOAT_EQ(corner[3], 0.f);
}

// --- Multipass equals single pass --------------------------------------------------------

TEST(Renderer, MultipassEqualsSinglepassForOneTwoAndManyPasses) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 4, 12, 4);
  const int K = s.set.cluster_count;
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  const Eigen::Matrix3d R = test_rotation();
  const render::Image single = render_once(ctx, s, options(render::Mode::kSinglepass), s.camera, R);
  const double scale = single.max_rgb();
  ASSERT_GT(scale, 0.0);
  // Both ways of shading a pass: by feedback into the radiance buffer, and in the draw.
  for (int per_pass : {K, (K + 1) / 2, 1})
    for (bool feedback : {true, false}) {
      render::RenderStats stats;
      render::RendererOptions o = options(render::Mode::kMultipass, per_pass * registers);
      o.multipass_feedback = feedback;
      const render::Image multi = render_once(ctx, s, o, s.camera, R, &stats);
      EXPECT_EQ(stats.passes, (K + per_pass - 1) / per_pass);
      EXPECT_LT(max_abs_difference(multi, single), image_tolerance(4, 4) * scale)
          << per_pass << " clusters per pass, feedback " << feedback;
    }
  // Alpha is coverage: both 0 and 1 occur, nothing else.
  int covered = 0;
  for (int i = 0; i < single.width * single.height; ++i) {
    const float a = single.rgba[std::size_t(i) * 4 + 3];
    EXPECT_TRUE(a == 0.f || a == 1.f);
    covered += a == 1.f;
  }
  EXPECT_GT(covered, 100);
  EXPECT_LT(covered, single.width * single.height);
}

TEST(Renderer, HalfFloatAccumulationKeepsElevenBits) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 4, 12, 4);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  const Eigen::Matrix3d R = test_rotation();
  // One cluster per pass: the most additions into the target.
  render::RendererOptions o = options(render::Mode::kMultipass, registers);
  render::RenderStats stats;
  o.accumulation = render::Accumulation::kAuto;
  render_once(ctx, s, o, s.camera, R, &stats);
  EXPECT_EQ(stats.accumulation, render::Accumulation::kFloat32) << "kAuto on llvmpipe";
  o.accumulation = render::Accumulation::kFloat32;
  const render::Image full = render_once(ctx, s, o, s.camera, R);
  o.accumulation = render::Accumulation::kFloat16;
  const render::Image half = render_once(ctx, s, o, s.camera, R, &stats);
  EXPECT_EQ(stats.accumulation, render::Accumulation::kFloat16);
  ASSERT_GT(stats.passes, 2);
  // Each of the passes' sums rounds to 11 significant bits: 2^-11 relative per addition.
  double worst = 0;
  bool differs = false;
  for (std::size_t i = 0; i < full.rgba.size(); ++i) {
    const double ref = full.rgba[i], got = half.rgba[i];
    worst = std::max(worst, std::abs(got - ref) / std::max(std::abs(ref), 1e-3));
    differs = differs || got != ref;
  }
  EXPECT_LT(worst, double(stats.passes) * std::ldexp(1.0, -11));
  EXPECT_TRUE(differs) << "the half-float target was not used";
}

TEST(Renderer, DecoupledCpuAndSinglepassImagesAgree) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_torus(1.f, 0.4f, 24, 12), 5, 10, 4);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  const Eigen::Matrix3d R = test_rotation();
  const render::Image single = render_once(ctx, s, options(render::Mode::kSinglepass), s.camera, R);
  const double scale = single.max_rgb();
  for (render::Mode mode : {render::Mode::kDecoupled, render::Mode::kCpu}) {
    render::RenderStats stats;
    render::RendererOptions o = options(mode, 2 * registers);
    o.count_primitives = true;
    const render::Image other = render_once(ctx, s, o, s.camera, R, &stats);
    EXPECT_LT(max_abs_difference(other, single), image_tolerance(5, 4) * scale)
        << render::kModeNames.name(mode);
    // Overdraw 1 means GL drew every triangle exactly once, whatever the stats say.
    ASSERT_EQ(stats.measured_triangles.size(), 1u) << render::kModeNames.name(mode);
    EXPECT_EQ(stats.measured_triangles[0], s.mesh.triangle_count())
        << render::kModeNames.name(mode);
  }
}

// --- Triangles drawn ---------------------------------------------------------------------

TEST(Renderer, TrianglesDrawnMatchTheClusterPrediction) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 3, 10, 2);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  std::vector<cpca::TriangleIndices> tris(s.mesh.triangles.begin(), s.mesh.triangles.end());
  for (int per_pass : {1, 3}) {
    render::RendererOptions o = options(render::Mode::kMultipass, per_pass * registers);
    o.count_primitives = true;
    // A grouping other than cluster order: odd clusters first, to show the strategy is used.
    cpca::SuperClusters groups;
    std::vector<std::uint32_t> order;
    for (int k = 1; k < s.set.cluster_count; k += 2) order.push_back(std::uint32_t(k));
    for (int k = 0; k < s.set.cluster_count; k += 2) order.push_back(std::uint32_t(k));
    for (std::size_t i = 0; i < order.size(); ++i) {
      if (i % std::size_t(per_pass) == 0) groups.passes.emplace_back();
      groups.passes.back().push_back(order[i]);
    }
    o.groups = groups;
    render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, o);
    r.render(s.camera, s.lighting, Eigen::Matrix3d::Identity());
    // The oracle, by brute force: a pass draws every triangle with a vertex in its clusters.
    std::vector<std::uint64_t> expected(groups.passes.size(), 0);
    std::uint64_t total = 0;
    for (const cpca::TriangleIndices& t : tris)
      for (std::size_t p = 0; p < groups.passes.size(); ++p) {
        const auto& pass = groups.passes[p];
        const bool touches = std::any_of(t.begin(), t.end(), [&](std::uint32_t v) {
          return std::find(pass.begin(), pass.end(), s.set.cluster_of[v]) != pass.end();
        });
        expected[p] += touches;
        total += touches;
      }
    EXPECT_EQ(r.stats().triangles_per_pass, expected);
    EXPECT_EQ(r.stats().measured_triangles, expected);
    EXPECT_DOUBLE_EQ(r.stats().average_overdraw, double(total) / double(tris.size()));
    EXPECT_GT(total, tris.size());
  }
}

// --- Rotation symmetry ---------------------------------------------------------------------

TEST(Renderer, RotatingProbeAndCameraTogetherLeavesTheSphereUnchanged) {
  render::GlContext ctx;
  // Lossless compression (groups of 6, 5 PCs), so only the renderer is under test.
  Scene s = make_scene(meshes::make_sphere(1.f, 48, 24), 4, 6, 5);
  s.camera = render::frame_sphere(Eigen::Vector3d::Zero(), 1.0, 96, 72);
  const Eigen::Matrix3d R = prt::axis_angle(Eigen::Vector3d(1, -2, 0.5).normalized(), 0.9);
  const render::RendererOptions o = options(render::Mode::kSinglepass);
  const render::Image base = render_once(ctx, s, o, s.camera, Eigen::Matrix3d::Identity());
  const render::Image both = render_once(ctx, s, o, render::rotated(s.camera, R), R);
  const render::Image camera_only =
      render_once(ctx, s, o, render::rotated(s.camera, R), Eigen::Matrix3d::Identity());
  auto mean_difference = [&](const render::Image& a) {
    double diff = 0.0, sum = 0.0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i) {
      if (i % 4 == 3) continue;
      diff += std::abs(a.rgba[i] - base.rgba[i]);
      sum += std::abs(base.rgba[i]);
    }
    return diff / sum;
  };
  // Tessellation and per-vertex interpolation are not rotation invariant: silhouettes and
  // shading move by a fraction of a triangle. 1% of the mean radiance allows that; a wrong
  // rotation convention changes the image by far more (checked just below).
  const double together = mean_difference(both);
  EXPECT_LT(together, 0.01);
  EXPECT_GT(mean_difference(camera_only), 10 * together);
}

// --- Background ------------------------------------------------------------------------------

// The uniform cubic B-spline kernel, in its closed form by distance: an oracle written apart
// from the renderer's separable weights.
double cubic_bspline(double t) {
  t = std::abs(t);
  if (t < 1) return 2.0 / 3.0 - t * t + t * t * t / 2;
  return t < 2 ? (2 - t) * (2 - t) * (2 - t) / 6 : 0.0;
}

// The background's filter: the probe's texels, weighted by the kernel of their distance from
// the lat-long point of direction d (texel centres at half-integers, wrapping in u, clamping
// in v).
probes::Rgb bspline_lookup(const probes::Probe& probe, const Eigen::Vector3d& d) {
  const double u = std::atan2(-d.x(), d.z()) / (2 * std::numbers::pi);
  const double px = (u < 0 ? u + 1 : u) * probe.width() - 0.5;
  const double py =
      std::acos(std::clamp(d.y(), -1.0, 1.0)) / std::numbers::pi * probe.height() - 0.5;
  probes::Rgb sum = probes::Rgb::Zero();
  for (int y = int(std::floor(py)) - 1; y <= int(std::floor(py)) + 2; ++y)
    for (int x = int(std::floor(px)) - 1; x <= int(std::floor(px)) + 2; ++x) {
      const int wrapped = (x % probe.width() + probe.width()) % probe.width();
      sum += float(cubic_bspline(px - x) * cubic_bspline(py - y)) *
             probe.texel(wrapped, std::clamp(y, 0, probe.height() - 1));
    }
  return sum;
}

TEST(Renderer, BackgroundIsTheRotatedProbe) {
  render::GlContext ctx;
  Scene s = make_scene(meshes::make_sphere(0.2f, 8, 4), 2, 8, 1);
  s.camera = render::frame_sphere(Eigen::Vector3d::Zero(), 3.0, 40, 30, 60.0);
  const Eigen::Matrix3d R = test_rotation();
  const render::Image image = render_once(ctx, s, options(render::Mode::kSinglepass), s.camera, R);
  for (auto [x, y] : {std::pair{0, 0}, {39, 0}, {0, 29}, {39, 29}, {5, 20}}) {
    const Eigen::Vector3d w = s.camera.pixel_direction(x, y);
    const probes::Rgb expected = bspline_lookup(s.probe, R.transpose() * w);
    const float* px = image.pixel(x, y);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(px[c], expected[c], 2e-3 * expected.maxCoeff()) << x << "," << y;
    EXPECT_EQ(px[3], 0.f);
  }
  // Solid colour replaces it.
  render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, options(render::Mode::kSinglepass));
  r.set_background({false, render::Rgb(0.25f, 0.5f, 0.75f)});
  r.render(s.camera, s.lighting, R);
  const render::Image solid = r.read_image();
  EXPECT_EQ(solid.pixel(0, 0)[0], 0.25f);
  EXPECT_EQ(solid.pixel(0, 0)[2], 0.75f);
}

// A viewer switches probes on a live renderer: the background is then the new probe's, as
// the same B-spline lookup predicts, and no longer the old one's.
TEST(Renderer, SetProbeReplacesTheBackground) {
  render::GlContext ctx;
  Scene s = make_scene(meshes::make_sphere(0.2f, 8, 4), 2, 8, 1);
  s.camera = render::frame_sphere(Eigen::Vector3d::Zero(), 3.0, 40, 30, 60.0);
  const probes::Probe other = probes::make_from_function(32, 16, [](const Eigen::Vector3d& d) {
    return probes::Rgb(float(1.5 + d.x()), float(0.2 + 0.1 * d.y()), 3.f);
  });
  const Eigen::Matrix3d R = test_rotation();
  render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, options(render::Mode::kSinglepass));
  r.render(s.camera, s.lighting, R);
  r.set_probe(&other);
  r.render(s.camera, s.lighting, R);
  const render::Image image = r.read_image();
  for (auto [x, y] : {std::pair{0, 0}, {39, 0}, {0, 29}, {39, 29}, {5, 20}}) {
    const Eigen::Vector3d w = R.transpose() * s.camera.pixel_direction(x, y);
    const probes::Rgb expected = bspline_lookup(other, w);
    const probes::Rgb old = bspline_lookup(s.probe, w);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(image.pixel(x, y)[c], expected[c], 2e-3 * expected.maxCoeff()) << x << "," << y;
    EXPECT_GT((old - expected).cwiseAbs().maxCoeff(), 0.1f);  // the test can tell them apart
  }
}

// The probe background replaces the colour clear, so every pixel of a frame must be written by
// the background or by the mesh over it: a frame after one from another viewpoint (the mesh
// elsewhere on screen, a different rotation) equals the same frame from a fresh renderer,
// in every mode, bit for bit.
TEST(Renderer, ProbeBackgroundLeavesNothingOfTheLastFrame) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_sphere(1.f, 16, 8), 3, 8, 2);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  render::Camera before = s.camera;  // the sphere in a corner, seen from elsewhere
  before.target += 0.6 * Eigen::Vector3d(1.0, 0.8, 0.0);
  before.eye += Eigen::Vector3d(0.4, 0.8, 0.0);
  for (render::Mode mode : {render::Mode::kMultipass, render::Mode::kSinglepass,
                            render::Mode::kDecoupled, render::Mode::kCpu}) {
    const render::RendererOptions o = options(mode, 3 * registers);
    render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, o);
    r.render(before, s.lighting, Eigen::Matrix3d::Identity());
    const render::Image first = r.read_image();
    r.render(s.camera, s.lighting, test_rotation());
    const render::Image second = r.read_image();
    const render::Image fresh = render_once(ctx, s, o, s.camera, test_rotation());
    // The test can tell: pixels the mesh covered first are background now, and the reverse.
    int uncovered = 0, covered = 0;
    for (int y = 0; y < fresh.height; ++y)
      for (int x = 0; x < fresh.width; ++x) {
        uncovered += first.pixel(x, y)[3] == 1.f && fresh.pixel(x, y)[3] == 0.f;
        covered += first.pixel(x, y)[3] == 0.f && fresh.pixel(x, y)[3] == 1.f;
      }
    ASSERT_GT(uncovered, 50) << render::kModeNames.name(mode);
    ASSERT_GT(covered, 50) << render::kModeNames.name(mode);
    EXPECT_EQ(max_abs_difference(second, fresh), 0.0) << render::kModeNames.name(mode);
  }
}

// Magnified texels of a checkerboard probe: the image follows the B-spline, and so is not
// the bilinear lookup (which the smooth test probe above cannot tell apart).
TEST(Renderer, MagnifiedBackgroundIsBsplineNotBilinear) {
  render::GlContext ctx;
  Scene s = make_scene(meshes::make_sphere(0.2f, 8, 4), 2, 8, 1);
  s.probe = probes::make_from_function(16, 8, [](const Eigen::Vector3d& d) {
    const double theta = std::acos(std::clamp(d.y(), -1.0, 1.0));
    const double phi = std::atan2(-d.x(), d.z()) + std::numbers::pi;
    const bool on = (int(phi / (std::numbers::pi / 8)) + int(theta / (std::numbers::pi / 8))) % 2;
    return probes::Rgb(on ? 4.f : 0.5f, 1.f, 1.f);
  });
  s.camera = render::frame_sphere(Eigen::Vector3d::Zero(), 3.0, 40, 30, 60.0);
  const Eigen::Matrix3d R = test_rotation();
  const render::Image image = render_once(ctx, s, options(render::Mode::kSinglepass), s.camera, R);
  double worst_bspline = 0.0, worst_bilinear = 0.0;
  for (int y = 0; y < 30; y += 3)
    for (int x = 0; x < 40; x += 3) {
      const Eigen::Vector3d w = R.transpose() * s.camera.pixel_direction(x, y);
      const float r = image.pixel(x, y)[0];
      if (image.pixel(x, y)[3] != 0.f) continue;  // the sphere
      worst_bspline = std::max(worst_bspline, std::abs(double(r - bspline_lookup(s.probe, w)[0])));
      worst_bilinear = std::max(worst_bilinear, std::abs(double(r - s.probe.lookup(w)[0])));
    }
  EXPECT_LT(worst_bspline, 2e-3 * 4.0);
  EXPECT_GT(worst_bilinear, 0.1);
}

// A real probe at the main job's magnification (1280 x 948 at 40 degrees: a pixel spans
// 0.00074 rad, a texel of the 1024-wide probe 0.0061): the cube map's single tap stays close
// to the B-spline it samples, over every background pixel.
TEST(Renderer, RealProbeBackgroundFollowsTheBspline) {
  const std::filesystem::path forest = "/usr/share/blender/datafiles/studiolights/world/forest.exr";
  if (!std::filesystem::exists(forest)) GTEST_SKIP() << forest << " is absent (blender-data)";
  render::GlContext ctx;
  Scene s = make_scene(meshes::make_sphere(0.2f, 8, 4), 2, 8, 1);
  s.probe = probes::load_probe(forest);
  s.camera = render::frame_sphere(Eigen::Vector3d::Zero(), 3.0, 320, 237, 10.0);
  const Eigen::Matrix3d R = test_rotation();
  const render::Image image = render_once(ctx, s, options(render::Mode::kSinglepass), s.camera, R);
  std::vector<double> errors;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      if (image.pixel(x, y)[3] != 0.f) continue;
      const probes::Rgb expected =
          bspline_lookup(s.probe, R.transpose() * s.camera.pixel_direction(x, y));
      const double scale = std::max(1e-3, double(expected.maxCoeff()));
      double e = 0;
      for (int c = 0; c < 3; ++c)
        e = std::max(e, std::abs(image.pixel(x, y)[c] - expected[c]) / scale);
      errors.push_back(e);
    }
  ASSERT_GT(errors.size(), 50000u);
  std::sort(errors.begin(), errors.end());
  const double p99 = errors[errors.size() * 99 / 100], worst = errors.back();
  double mean = 0;
  for (double e : errors) mean += e / double(errors.size());
  std::printf("background vs B-spline: mean %.5f, p99 %.5f, max %.5f (relative)\n", mean, p99,
              worst);
  EXPECT_LT(p99, 0.025);
  EXPECT_LT(worst, 0.06);
}

TEST(Renderer, SolidBackgroundDoesNotLeakIntoAdditivePasses) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_torus(1.f, 0.4f, 16, 8), 3, 8, 2);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  const render::Background grey{false, render::Rgb(0.5f, 0.5f, 0.5f)};
  auto image = [&](render::Mode mode) {
    render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, options(mode, 2 * registers));
    r.set_background(grey);
    r.render(s.camera, s.lighting, test_rotation());
    return r.read_image();
  };
  const render::Image single = image(render::Mode::kSinglepass);
  const render::Image multi = image(render::Mode::kMultipass);
  EXPECT_LT(max_abs_difference(multi, single), image_tolerance(3, 2) * single.max_rgb());
  EXPECT_EQ(single.pixel(0, 0)[1], 0.5f);
  EXPECT_EQ(single.pixel(0, 0)[3], 0.f);
}

// --- Compression error ---------------------------------------------------------------------

TEST(Renderer, CompressedErrorFallsAsComponentsAndClustersGrow) {
  render::GlContext ctx;
  Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 4, 8, 1);
  const Eigen::Matrix3d R = test_rotation();
  const render::Image truth =
      render_once(ctx, s, options(render::Mode::kUncompressed), s.camera, R);
  auto error_of = [&](int group, int components) {
    s.set = compress_by_groups(s.transfer, group, components);
    const render::Image img = render_once(ctx, s, options(render::Mode::kSinglepass), s.camera, R);
    double e = 0.0;
    for (std::size_t i = 0; i < img.rgba.size(); ++i) {
      const double d = img.rgba[i] - truth.rgba[i];
      e += d * d;
    }
    return std::sqrt(e / double(img.rgba.size()));
  };
  // More PCs at a fixed clustering (nested subspaces).
  const double pcs1 = error_of(32, 1), pcs3 = error_of(32, 3), pcs8 = error_of(32, 8);
  EXPECT_LT(pcs3, pcs1);
  EXPECT_LT(pcs8, pcs3);
  // More clusters at a fixed PC count (nested partitions: 64 -> 16 -> 4 vertices each).
  const double k64 = error_of(64, 2), k16 = error_of(16, 2), k4 = error_of(4, 2);
  EXPECT_LT(k16, k64);
  EXPECT_LT(k4, k16);
  // Groups of 4 with 3 PCs are lossless: what is left is the two paths' float rounding.
  EXPECT_LT(error_of(4, 3), 1e-4 * truth.max_rgb());
  EXPECT_LT(error_of(4, 3), 0.01 * k4);
}

// --- Errors --------------------------------------------------------------------------------

TEST(Renderer, RejectsBudgetsBelowOneCluster) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_sphere(1.f, 8, 4), 3, 8, 2);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  EXPECT_THROW(render::Renderer(s.mesh, &s.set, nullptr, nullptr,
                                options(render::Mode::kMultipass, registers - 1)),
               std::invalid_argument);
  EXPECT_THROW(
      render::Renderer(s.mesh, nullptr, nullptr, nullptr, options(render::Mode::kUncompressed)),
      std::invalid_argument);
  EXPECT_THROW(render::kModeNames.parse("fast"), std::invalid_argument);
}

// --- Backends -------------------------------------------------------------------------------

// OSMesa and EGL (Mesa's software device here, a GPU's driver elsewhere) render the same
// image: every mode, the same scene, 1e-5 of the brightest pixel. Both run llvmpipe on this
// machine, so the bound is float rounding, not a tolerance for a different rasteriser.
TEST(Renderer, OsmesaAndEglRenderTheSameImage) {
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 4, 10, 3);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  auto render_all = [&](render::GlBackend backend) {
    render::GlContext ctx({backend});
    std::vector<render::Image> images;
    for (render::Mode mode :
         {render::Mode::kMultipass, render::Mode::kSinglepass, render::Mode::kDecoupled,
          render::Mode::kUncompressed, render::Mode::kCpu})
      images.push_back(
          render_once(ctx, s, options(mode, 3 * registers), s.camera, test_rotation()));
    return images;
  };
  const std::vector<render::Image> osmesa = render_all(render::GlBackend::kOsmesa);
  const std::vector<render::Image> egl = render_all(render::GlBackend::kEgl);
  ASSERT_EQ(osmesa.size(), egl.size());
  for (std::size_t m = 0; m < osmesa.size(); ++m) {
    ASSERT_EQ(osmesa[m].width, egl[m].width);
    ASSERT_EQ(osmesa[m].height, egl[m].height);
    double peak = 0.0;
    for (float v : osmesa[m].rgba) peak = std::max(peak, double(std::abs(v)));
    ASSERT_GT(peak, 0.0);
    EXPECT_LE(max_abs_difference(egl[m], osmesa[m]) / peak, 1e-5) << "mode " << m;
  }
}

}  // namespace

// --- Pipeline statistics -------------------------------------------------------------------

// The counters' oracles: a draw submits exactly its triangles, no draw shades fewer vertices
// than it references, and the decoupled feedback draw shades each vertex exactly once.
TEST(Renderer, WorkCountersMatchTheDrawsTheyBracket) {
  render::GlContext ctx;
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 3, 10, 2);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  for (render::Mode mode : {render::Mode::kMultipass, render::Mode::kSinglepass,
                            render::Mode::kDecoupled, render::Mode::kCpu}) {
    render::RendererOptions o = options(mode, 3 * registers);
    o.count_work = true;
    render::Renderer r(s.mesh, &s.set, nullptr, &s.probe, o);
    r.render(s.camera, s.lighting, Eigen::Matrix3d::Identity());
    const render::RenderStats& st = r.stats();
    ASSERT_FALSE(st.pass_work.empty()) << render::kModeNames.name(mode);
    std::uint64_t shaded_triangles = 0;
    for (const render::PassWork& p : st.pass_work) {
      if (p.label == "background") {
        EXPECT_EQ(p.primitives, 1u);
        EXPECT_GT(p.fs_invocations, 0u);
        continue;
      }
      EXPECT_GE(p.vs_invocations, p.referenced_vertices)
          << render::kModeNames.name(mode) << p.label;
      if (p.label == "feedback") {
        EXPECT_EQ(p.vs_invocations, s.mesh.vertex_count());
        EXPECT_EQ(p.primitives, s.mesh.vertex_count());
      } else if (p.label.starts_with("shade")) {
        shaded_triangles += p.primitives;
      } else {
        EXPECT_EQ(p.label, "depth");
        EXPECT_EQ(p.primitives, s.mesh.triangle_count());
      }
    }
    std::uint64_t predicted = 0;
    for (std::uint64_t t : st.triangles_per_pass) predicted += t;
    EXPECT_EQ(shaded_triangles, predicted) << render::kModeNames.name(mode);
    const render::WorkTotals totals = render::work_totals(st.pass_work);
    EXPECT_GE(totals.vs_per_referenced_vertex, 1.0);
  }
}

// --- GL debug output -------------------------------------------------------------------------

// Every path renders and captures without a KHR_debug error or undefined-behaviour message
// (the decoupled path once fed back into a buffer its VAO still sourced). The log itself is
// checked first: a deliberate invalid enum must reach it.
TEST(Renderer, EveryModeRunsWithoutDebugErrors) {
  render::GlContext ctx;
  {
    render::GlDebugLog probe_log;
    glEnable(0xFFFF);  // not a capability: GL_INVALID_ENUM
    EXPECT_FALSE(probe_log.messages().empty()) << "KHR_debug output is not delivered";
    while (glGetError() != GL_NO_ERROR) {
    }
  }
  const Scene s = make_scene(meshes::make_plane_and_sphere(3.f, 8, 0.5f, 1.0f, 16, 8), 3, 10, 2);
  const int registers = render::constant_layout(s.set).registers_per_cluster();
  for (render::Mode mode :
       {render::Mode::kMultipass, render::Mode::kSinglepass, render::Mode::kDecoupled,
        render::Mode::kUncompressed, render::Mode::kCpu}) {
    render::GlDebugLog log;
    render::RendererOptions o = options(mode, 3 * registers);
    o.count_work = true;
    render::Renderer r(s.mesh, &s.set, &s.transfer, &s.probe, o);
    r.render(s.camera, s.lighting, test_rotation());
    r.capture_vertex_radiance(s.camera, s.lighting, test_rotation());
    for (const std::string& m : log.messages())
      ADD_FAILURE() << render::kModeNames.name(mode) << ": " << m;
  }
}
