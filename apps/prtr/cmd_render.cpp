// prtr render COMPRESSED --probe PROBE -o out.exr: relight a compressed bake with OpenGL
// (OSMesa/llvmpipe), write linear EXR (+ tone-mapped PNG) and report passes, overdraw and
// frame times (issue 5; render/renderer.h describes the modes).
#include "commands.h"

#include "cpca/compressed_file.h"
#include "cpca/supercluster_strategy.h"
#include "meshes/load.h"
#include "probes/load.h"
#include "prt/projection.h"
#include "prt/sh_rotation.h"
#include "prt/transfer_file.h"
#include "render/camera.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "render/renderer.h"

#include <cstdio>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace prtr_app {
namespace {

std::vector<double> parse_numbers(const std::string& text, const char* flag, std::size_t count) {
  std::vector<double> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError(std::string(flag) + ": '" + text + "' is not a list of numbers");
    }
  }
  if (values.size() != count)
    throw UsageError(std::string(flag) + " takes " + std::to_string(count) +
                     " comma-separated numbers, got '" + text + "'");
  return values;
}

Eigen::Vector3d parse_vector(const std::string& text, const char* flag) {
  const std::vector<double> v = parse_numbers(text, flag, 3);
  return {v[0], v[1], v[2]};
}

std::string json_list(const std::vector<std::uint64_t>& values) {
  std::string s = "[";
  for (std::size_t i = 0; i < values.size(); ++i) s += (i ? "," : "") + std::to_string(values[i]);
  return s + "]";
}

}  // namespace

Runner add_render_command(CLI::App& app) {
  struct Options {
    std::string compressed, probe, mesh, transfer, output, png, mode = "multipass";
    std::string axis = "0,1,0", eye, target, up, background = "probe", strategy = "order";
    double rotate_deg = 0.0, fov = 40.0, exposure = 0.0, degrees_per_frame = 1.0;
    int register_budget = 0, clusters_per_pass = 0, frames = 20, warmup = 3;
    int width = 1280, height = 948;
    bool json = false, quiet = false, no_cull = false, no_reorder = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Relight a compressed bake (.prtc) under a rotated probe; write EXR/PNG and FPS");
  cmd->add_option("COMPRESSED", opt->compressed, "Compressed transfer file (.prtc)")->required();
  cmd->add_option("--probe", opt->probe, "Light probe (lat-long or angular EXR/HDR)")->required();
  cmd->add_option("-o,--output", opt->output, "EXR to write (linear RGB, alpha = coverage)")
      ->required();
  cmd->add_option("--png", opt->png, "Also write a tone-mapped PNG");
  cmd->add_option("--mesh", opt->mesh, "Mesh (default: the one the set was baked from)");
  cmd->add_option("--mode", opt->mode, "Rendering path")
      ->check(CLI::IsMember({"multipass", "singlepass", "decoupled", "uncompressed", "cpu"}))
      ->capture_default_str();
  cmd->add_option("--transfer", opt->transfer,
                  "Raw transfer file (.prtx), for --mode uncompressed");
  cmd->add_option("--rotate-deg", opt->rotate_deg, "Environment rotation angle (degrees)")
      ->capture_default_str();
  cmd->add_option("--axis", opt->axis, "Environment rotation axis x,y,z")->capture_default_str();
  cmd->add_option("--register-budget", opt->register_budget,
                  "vec4 registers per pass (0: what the GL context offers; thesis GPU: 256)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--clusters-per-pass", opt->clusters_per_pass,
                  "Clusters per pass (0: as many as the budget holds)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--strategy", opt->strategy,
                  "Super-cluster strategy: " + cpca::supercluster_strategy_names())
      ->capture_default_str();
  cmd->add_option("--frames", opt->frames, "Timed frames (median reported)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--warmup", opt->warmup, "Untimed frames first")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--spin-deg", opt->degrees_per_frame,
                  "Extra environment rotation per timed frame, so constants change every frame")
      ->capture_default_str();
  cmd->add_option("--width", opt->width, "Image width")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Image height")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--eye", opt->eye, "Camera position x,y,z (default: frames the bounding sphere)");
  cmd->add_option("--target", opt->target, "Camera target x,y,z (default: the sphere's centre)");
  cmd->add_option("--up", opt->up, "Camera up x,y,z (default: 0,1,0)");
  cmd->add_option("--fov", opt->fov, "Vertical field of view (degrees)")->capture_default_str();
  cmd->add_option("--background", opt->background, "probe, black, or a colour R,G,B")
      ->capture_default_str();
  cmd->add_option("--exposure", opt->exposure, "PNG exposure in stops")->capture_default_str();
  cmd->add_flag("--no-cull", opt->no_cull, "Draw back faces too (open meshes)");
  cmd->add_flag("--no-reorder", opt->no_reorder,
                "Keep triangles in mesh order (no vertex-cache order)");
  cmd->add_flag("--json", opt->json, "Print one JSON line of results");
  cmd->add_flag("-q,--quiet", opt->quiet, "Print nothing but errors (and the --json line)");

  return [opt, cmd] {
    Options& o = *opt;
    render::RendererOptions ro;
    ro.mode = render::parse_mode(o.mode);
    ro.register_budget = o.register_budget;
    ro.clusters_per_pass = o.clusters_per_pass;
    ro.cull_back_faces = !o.no_cull;
    ro.optimize_vertex_cache = !o.no_reorder;
    ro.count_primitives = ro.mode == render::Mode::kMultipass;
    if (ro.mode == render::Mode::kUncompressed && o.transfer.empty())
      throw UsageError("--mode uncompressed needs --transfer PRTX (the raw bake)");
    if (ro.mode != render::Mode::kUncompressed && !o.transfer.empty())
      throw UsageError("--transfer is only read by --mode uncompressed");
    if (ro.mode != render::Mode::kMultipass && ro.mode != render::Mode::kDecoupled &&
        (cmd->count("--clusters-per-pass") || cmd->count("--strategy")))
      throw UsageError("--clusters-per-pass and --strategy apply to multipass and decoupled only");
    try {
      cpca::find_supercluster_strategy(o.strategy);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    render::Background background;
    if (o.background == "probe") {
      background.use_probe = true;
    } else if (o.background == "black") {
      background.use_probe = false;
    } else {
      background.use_probe = false;
      background.colour = parse_vector(o.background, "--background").cast<float>();
    }
    const Eigen::Vector3d axis = parse_vector(o.axis, "--axis");
    if (!(axis.norm() > 0)) throw UsageError("--axis must not be the zero vector");

    const cpca::CompressedSet set = cpca::read_compressed(o.compressed);
    const std::string mesh_path = o.mesh.empty() ? set.mesh_path : o.mesh;
    if (mesh_path.empty())
      throw UsageError(o.compressed + " records no mesh path; pass --mesh MESH");
    const meshes::Mesh mesh = meshes::load_mesh(mesh_path);
    if (meshes::content_hash(mesh) != set.mesh_hash)
      throw std::runtime_error(o.compressed + " was baked from a different mesh than " + mesh_path +
                               " (stale); bake and compress it again, or pass the right --mesh");
    std::optional<prt::TransferSet> transfer;
    if (!o.transfer.empty()) {
      transfer = prt::read_transfer(o.transfer);
      if (transfer->mesh_hash != set.mesh_hash)
        throw std::runtime_error(o.transfer + " and " + o.compressed +
                                 " come from different meshes; use the bake the set was made from");
    }
    const probes::Probe probe = probes::load_probe(o.probe);
    const int order = transfer ? transfer->order : set.order;
    const prt::ShLighting lighting = prt::project(probe, order);
    const Eigen::Matrix3d rotation =
        prt::axis_angle(axis.normalized(), o.rotate_deg * std::numbers::pi / 180.0);

    const meshes::Bounds bounds = meshes::bounds(mesh);
    const Eigen::Vector3d centre = bounds.center().cast<double>();
    double radius = 0.0;
    for (const auto& p : mesh.positions)
      radius = std::max(radius, (p.cast<double>() - centre).norm());
    render::Camera camera = render::frame_sphere(centre, radius, o.width, o.height, o.fov);
    if (!o.target.empty()) camera.target = parse_vector(o.target, "--target");
    if (!o.eye.empty()) camera.eye = parse_vector(o.eye, "--eye");
    if (!o.up.empty()) camera.up = parse_vector(o.up, "--up");
    render::fit_clip_planes(camera, centre, radius);
    try {
      camera.validate();
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }

    render::GlContext context;
    if (ro.mode == render::Mode::kMultipass || ro.mode == render::Mode::kDecoupled) {
      // The strategy needs the pass capacity, which depends on the budget the renderer
      // resolves; a first renderer-free computation mirrors it.
      const render::ConstantLayout layout = render::constant_layout(set);
      const int budget =
          o.register_budget > 0 ? o.register_budget : context.info().max_vertex_uniform_vectors;
      int per_pass = budget / layout.registers_per_cluster();
      if (o.clusters_per_pass > 0) per_pass = std::min(per_pass, o.clusters_per_pass);
      if (per_pass >= 1 && o.strategy != "order") {
        std::vector<cpca::TriangleIndices> tris(mesh.triangles.begin(), mesh.triangles.end());
        cpca::SuperClusterInput input{set.cluster_of, tris, set.cluster_count, per_pass};
        ro.groups = cpca::group_clusters(o.strategy, input);
      }
    }
    std::optional<render::Renderer> renderer;
    try {
      renderer.emplace(mesh, &set, transfer ? &*transfer : nullptr, &probe, ro);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    renderer->set_background(background);
    const render::TimingSummary timing = render::measure(
        *renderer, camera, lighting, rotation, axis, o.degrees_per_frame, o.frames, o.warmup);
    renderer->render(camera, lighting, rotation);
    const render::Image image = renderer->read_image();
    render::write_exr(o.output, image);
    if (!o.png.empty()) render::write_png(o.png, image, o.exposure);

    const render::RenderStats& st = renderer->stats();
    if (!st.measured_triangles.empty() && st.measured_triangles != st.triangles_per_pass)
      throw std::runtime_error("GL counted " + json_list(st.measured_triangles) +
                               " triangles per pass but the grouping predicts " +
                               json_list(st.triangles_per_pass) + " (a renderer bug)");
    if (!o.quiet) {
      std::printf("rendered    %s -> %s%s%s (%d x %d)\n", o.compressed.c_str(), o.output.c_str(),
                  o.png.empty() ? "" : ", ", o.png.c_str(), o.width, o.height);
      std::printf(
          "mode        %s, %d pass(es), %d cluster(s) per pass, budget %d vec4 (%d per cluster)\n",
          o.mode.c_str(), st.passes, st.clusters_per_pass, st.register_budget,
          st.registers_per_cluster);
      std::printf("overdraw    %.4f (%llu triangles, drawn per pass %s)\n", st.average_overdraw,
                  static_cast<unsigned long long>(st.triangle_count),
                  json_list(st.triangles_per_pass).c_str());
      std::printf(
          "timing      %.2f FPS: frame %.2f ms median (cpu update %.2f ms, gl %.2f ms) over %d "
          "frames\n",
          timing.fps, timing.frame_ms_median, timing.cpu_ms_median, timing.gl_ms_median,
          timing.frames);
    }
    if (o.json) {
      std::printf(
          "{\"mode\":\"%s\",\"width\":%d,\"height\":%d,\"passes\":%d,\"triangles_per_pass\":%s,"
          "\"average_overdraw\":%.6f,\"fps\":%.3f,\"frame_ms_median\":%.3f,"
          "\"cpu_update_ms\":%.3f,\"gl_ms\":%.3f}\n",
          o.mode.c_str(), o.width, o.height, st.passes, json_list(st.triangles_per_pass).c_str(),
          st.average_overdraw, timing.fps, timing.frame_ms_median, timing.cpu_ms_median,
          timing.gl_ms_median);
    }
  };
}

}  // namespace prtr_app
