// prtr render COMPRESSED --probe PROBE -o out.exr: relight a compressed bake with OpenGL
// (OSMesa/llvmpipe), write linear EXR (+ tone-mapped PNG) and report passes, overdraw and
// frame times (render/renderer.h describes the modes).
#include "commands.h"
#include "common/json.h"
#include "flag_checks.h"
#include "gl_flags.h"
#include "mesh_flags.h"
#include "render/pass_grouping.h"
#include "slf_input.h"
#include "supersample_flag.h"
#include "view_flags.h"

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
#include "render/slf_renderer.h"
#include "render/supersample.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace prtr_app {
using common::dump_json;
using common::Json;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_render {

// "[a,b,c]": the per-pass triangle counts, as the text report and error messages show them.
std::string count_list(const std::vector<std::uint64_t>& values) {
  return dump_json(Json(values));
}

struct Options {
  std::string compressed, probe, mesh, transfer, output, png, mode = "multipass";
  std::string strategy = "order", accumulation = "auto", constants = "auto";
  std::string slf_shading = "auto";
  ViewFlags view;
  GlFlags gl;
  MeshFlags mesh_flags;
  double rotate_deg = 0.0, degrees_per_frame = 1.0;
  int register_budget = 0, clusters_per_pass = 0, frames = 20, warmup = 3;
  // The written image only: timing frames stay at --width x --height.
  int supersample = kDefaultSupersample;
  bool json = false, quiet = false, no_cull = false, no_reorder = false;
};

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("COMPRESSED", o.compressed,
                  "Compressed transfer (.prtc) or surface light field (.slfc)")
      ->required();
  cmd->add_option("--probe", o.probe, "Light probe (lat-long or angular EXR/HDR)")->required();
  cmd->add_option("-o,--output", o.output, "EXR to write (linear RGB, alpha = coverage)")
      ->required();
  cmd->add_option("--png", o.png, "Also write a tone-mapped PNG");
  add_supersample_flag(cmd, o.supersample);
  cmd->add_option("--mesh", o.mesh, "Mesh (default: the one the set was baked from)");
  add_mesh_flags(cmd, o.mesh_flags);
  add_checked_option(cmd, "--mode", o.mode, "Rendering path",
                     CLI::IsMember(render::kModeNames.names()));
  add_checked_option(cmd, "--slf-shading", o.slf_shading,
                     "Surface light fields (.slfc): where the reconstruction runs "
                     "(render/slf_renderer.h; auto: per frame, by cost)",
                     CLI::IsMember(render::kSlfShadingNames.names()));
  cmd->add_option("--transfer", o.transfer, "Raw transfer file (.prtx), for --mode uncompressed");
  add_checked_option(cmd, "--rotate-deg", o.rotate_deg, "Environment rotation angle (degrees)",
                     angle_degrees());
  cmd->add_option("--register-budget", o.register_budget,
                  "vec4 registers per pass (0: what the GL context offers; thesis GPU: 256)")
      ->check(integer_in(0, 1 << 20))
      ->capture_default_str();
  add_checked_option(cmd, "--clusters-per-pass", o.clusters_per_pass,
                     "Clusters per pass (0: as many as the budget holds)", integer_in(0, 1 << 20));
  cmd->add_option("--strategy", o.strategy,
                  "Super-cluster strategy: " + cpca::supercluster_strategy_names())
      ->capture_default_str();
  add_checked_option(cmd, "--frames", o.frames, "Timed frames (median reported)",
                     integer_in(1, 100000));
  add_checked_option(cmd, "--warmup", o.warmup, "Untimed frames first", integer_in(0, 100000));
  add_checked_option(cmd, "--spin-deg", o.degrees_per_frame,
                     "Extra environment rotation per timed frame, so constants change every frame",
                     angle_degrees());
  add_view_flags(cmd, o.view);
  cmd->add_flag("--no-cull", o.no_cull, "Draw back faces too (open meshes)");
  cmd->add_flag("--no-reorder", o.no_reorder,
                "Keep triangles in mesh order (no vertex-cache order)");
  add_gl_flags(cmd, o.gl);
  add_accumulation_flag(cmd, o.accumulation);
  add_constants_flag(cmd, o.constants);
  cmd->add_flag("--json", o.json, "Print one JSON line of results");
  cmd->add_flag("-q,--quiet", o.quiet, "Print nothing but errors (and the --json line)");
}

// The renderer options the flags describe; usage errors for flags the mode does not read.
render::RendererOptions renderer_options(const Options& o, const CLI::App* cmd) {
  render::RendererOptions ro;
  ro.mode = render::kModeNames.parse(o.mode);
  ro.accumulation = render::kAccumulationNames.parse(o.accumulation);
  ro.constants = render::kConstantsNames.parse(o.constants);
  ro.register_budget = o.register_budget;
  ro.clusters_per_pass = o.clusters_per_pass;
  ro.cull_back_faces = !o.no_cull;
  ro.optimize_vertex_cache = !o.no_reorder;
  if (ro.mode == render::Mode::kUncompressed && o.transfer.empty())
    throw UsageError("--mode uncompressed needs --transfer PRTX (the raw bake)");
  if (ro.mode != render::Mode::kUncompressed && !o.transfer.empty())
    throw UsageError("--transfer is only read by --mode uncompressed");
  if (ro.mode != render::Mode::kMultipass && ro.mode != render::Mode::kDecoupled &&
      (cmd->count("--clusters-per-pass") || cmd->count("--strategy")))
    throw UsageError("--clusters-per-pass and --strategy apply to multipass and decoupled only");
  return ro;
}

// The set's mesh (or --mesh), checked against the set's hash.
meshes::Mesh load_checked_mesh(const Options& o, const cpca::CompressedSet& set) {
  const std::string mesh_path = o.mesh.empty() ? set.mesh_path : o.mesh;
  if (mesh_path.empty()) throw UsageError(o.compressed + " records no mesh path; pass --mesh MESH");
  meshes::Mesh mesh = meshes::load_mesh(mesh_path, load_options(o.mesh_flags));
  if (meshes::content_hash(mesh) != set.mesh_hash)
    throw std::runtime_error(o.compressed + " was baked from a different mesh than " + mesh_path +
                             " (stale); bake and compress it again, or pass the right --mesh "
                             "(and the --crease-angle it was baked with)");
  if (mesh.vertex_count() != set.vertex_count)
    throw std::runtime_error(o.compressed + " holds " + std::to_string(set.vertex_count) +
                             " vertices, but " + mesh_path + " has " +
                             std::to_string(mesh.vertex_count()) +
                             " with the same hash; the set is damaged, compress it again");
  return mesh;
}

std::optional<prt::TransferSet> load_checked_transfer(const Options& o,
                                                      const cpca::CompressedSet& set) {
  if (o.transfer.empty()) return std::nullopt;
  prt::TransferSet transfer = prt::read_transfer(o.transfer);
  if (transfer.mesh_hash != set.mesh_hash || transfer.vertex_count != set.vertex_count)
    throw std::runtime_error(o.transfer + " and " + o.compressed +
                             " come from different meshes (hash or vertex count differ); use "
                             "the bake the set was made from");
  return transfer;
}

// The image frame's pipeline statistics: totals, then per draw in draw order.
void add_work(Json& line, const std::vector<render::PassWork>& work) {
  const render::WorkTotals t = render::work_totals(work);
  line["vs_invocations"] = t.vs_invocations;
  line["referenced_vertices"] = t.referenced_vertices;
  line["vs_per_referenced_vertex"] = t.vs_per_referenced_vertex;
  line["primitives"] = t.primitives;
  line["fs_invocations"] = t.fs_invocations;
  Json labels = Json::array(), vs = Json::array(), ref = Json::array(), prims = Json::array(),
       fs = Json::array();
  for (const render::PassWork& p : work) {
    labels.push_back(p.label);
    vs.push_back(p.vs_invocations);
    ref.push_back(p.referenced_vertices);
    prims.push_back(p.primitives);
    fs.push_back(p.fs_invocations);
  }
  line["draw_labels"] = labels;
  line["vs_invocations_per_draw"] = vs;
  line["referenced_vertices_per_draw"] = ref;
  line["primitives_per_draw"] = prims;
  line["fs_invocations_per_draw"] = fs;
}

void print_report(const Options& o, const render::RenderStats& st,
                  const render::TimingSummary& timing, double image_ms, double downsample_ms) {
  if (!o.quiet) {
    std::printf("rendered    %s -> %s%s%s (%d x %d)\n", o.compressed.c_str(), o.output.c_str(),
                o.png.empty() ? "" : ", ", o.png.c_str(), o.view.width, o.view.height);
    std::printf(
        "mode        %s, %d pass(es), %d cluster(s) per pass, budget %d vec4 (%d per cluster), "
        "%s target, constants on the %s\n",
        o.mode.c_str(), st.passes, st.clusters_per_pass, st.register_budget,
        st.registers_per_cluster, render::kAccumulationNames.name(st.accumulation),
        render::kConstantsNames.name(st.constants));
    std::printf("overdraw    %.4f (%llu triangles, drawn per pass %s)\n", st.average_overdraw,
                static_cast<unsigned long long>(st.triangle_count),
                count_list(st.triangles_per_pass).c_str());
    std::printf(
        "timing      %.2f FPS: frame %.2f ms median (cpu update %.2f ms, gl %.2f ms) over %d "
        "frames\n",
        timing.fps, timing.frame_ms_median, timing.cpu_ms_median, timing.gl_ms_median,
        timing.frames);
    std::printf(
        "image       %d x %d samples per pixel, %.2f ms for the written frame, %.2f ms to "
        "box-filter it\n",
        o.supersample, o.supersample, image_ms, downsample_ms);
  }
  if (o.json) {
    Json line = {{"mode", o.mode},
                 {"width", o.view.width},
                 {"height", o.view.height},
                 {"passes", st.passes},
                 {"triangles_per_pass", st.triangles_per_pass},
                 {"average_overdraw", st.average_overdraw},
                 {"fps", timing.fps},
                 {"frame_ms_median", timing.frame_ms_median},
                 {"cpu_update_ms", timing.cpu_ms_median},
                 {"gl_ms", timing.gl_ms_median}};
    add_work(line, st.pass_work);
    line["supersample"] = o.supersample;
    line["accumulation"] = render::kAccumulationNames.name(st.accumulation);
    line["constants"] = render::kConstantsNames.name(st.constants);
    line["image_frame_ms"] = image_ms;
    line["downsample_ms"] = downsample_ms;
    std::printf("%s\n", dump_json(line).c_str());
  }
}

// prtr render SET.slfc: the surface light field seen from the camera in one pass. Its
// lighting is baked, so only the camera moves; the probe is the background and must be the
// one it was baked under.
void run_slf(const Options& o, CLI::App* cmd) {
  for (const char* flag :
       {"--mode", "--transfer", "--rotate-deg", "--spin-deg", "--register-budget",
        "--clusters-per-pass", "--strategy", "--accumulation", "--constants"})
    if (cmd->count(flag))
      throw UsageError(std::string(flag) + " applies to PRT sets (.prtc); " + o.compressed +
                       " is a surface light field, whose lighting is baked and which renders "
                       "in one pass");
  const render::GlSelection gl = gl_selection(o.gl);
  const SlfInput input = load_slf_input(o.compressed, o.mesh, o.mesh_flags, o.probe);
  const pipeline::CompressedSlf& slf = input.slf;
  const meshes::Mesh& mesh = input.mesh;
  const probes::Probe& probe = input.probe;
  const render::SlfModel& model = input.model;
  const render::Background background = resolve_background(o.view);
  const render::Camera camera = resolve_camera(o.view, mesh);

  render::GlContext context(gl);
  render::SlfRendererOptions ro;
  ro.cull_back_faces = !o.no_cull;
  ro.shading = render::kSlfShadingNames.parse(o.slf_shading);
  render::SlfRenderer renderer(model, &probe, ro);
  renderer.set_background(background);
  for (int i = 0; i < o.warmup; ++i) renderer.render(camera);
  std::vector<double> frame_ms;
  for (int i = 0; i < o.frames; ++i) frame_ms.push_back(renderer.render(camera).total_ms);
  std::sort(frame_ms.begin(), frame_ms.end());
  const double median = frame_ms.empty() ? 0.0 : frame_ms[frame_ms.size() / 2];
  const double image_ms = renderer.render(render::supersampled(camera, o.supersample)).total_ms;
  const render::Image image = render::box_downsample(renderer.read_image(), o.supersample);
  render::write_exr(o.output, image);
  if (!o.png.empty()) render::write_png(o.png, image, o.view.exposure);
  if (!o.quiet) {
    std::printf("rendered    %s -> %s%s%s (%d x %d)\n", o.compressed.c_str(), o.output.c_str(),
                o.png.empty() ? "" : ", ", o.png.c_str(), o.view.width, o.view.height);
    std::printf(
        "slf         %s shading, %d cluster(s), %d PCA term(s), %d x %d texels, %d x %d "
        "directions, baked under %s\n",
        render::kSlfShadingNames.name(renderer.shading()), model.clusters, model.components,
        model.map_width, model.map_height, model.grid.azimuth, model.grid.elevation,
        slf.probe_name.c_str());
    std::printf("timing      %.2f FPS: frame %.2f ms median over %d frames\n",
                median > 0 ? 1000.0 / median : 0.0, median, o.frames);
    std::printf("image       %d x %d samples per pixel, %.2f ms for the written frame\n",
                o.supersample, o.supersample, image_ms);
  }
  if (o.json)
    std::printf("%s\n",
                dump_json(Json{{"mode", "slf"},
                               {"width", o.view.width},
                               {"height", o.view.height},
                               {"passes", 1},
                               {"shading", render::kSlfShadingNames.name(renderer.shading())},
                               {"clusters", model.clusters},
                               {"components", model.components},
                               {"fps", median > 0 ? 1000.0 / median : 0.0},
                               {"frame_ms_median", median},
                               {"supersample", o.supersample},
                               {"image_frame_ms", image_ms}})
                    .c_str());
}

void run(const Options& o, CLI::App* cmd) {
  check_outputs({{"-o", o.output}, {"--png", o.png}}, {{"COMPRESSED", o.compressed},
                                                       {"--probe", o.probe},
                                                       {"--mesh", o.mesh},
                                                       {"--transfer", o.transfer}});
  if (is_slfc(o.compressed)) return run_slf(o, cmd);
  if (cmd->count("--slf-shading"))
    throw UsageError("--slf-shading applies to surface light fields (.slfc); " + o.compressed +
                     " is a PRT set: choose its path with --mode");
  const render::GlSelection gl = gl_selection(o.gl);
  render::RendererOptions ro = renderer_options(o, cmd);
  const render::Background background = resolve_background(o.view);
  const Eigen::Vector3d axis = resolve_axis(o.view);
  const cpca::CompressedSet set = cpca::read_compressed(o.compressed);
  const meshes::Mesh mesh = load_checked_mesh(o, set);
  const std::optional<prt::TransferSet> transfer = load_checked_transfer(o, set);
  const probes::Probe probe = probes::load_probe(o.probe);
  const prt::ShLighting lighting = prt::project(probe, transfer ? transfer->order : set.order);
  const Eigen::Matrix3d rotation = prt::axis_angle(axis, o.rotate_deg * std::numbers::pi / 180.0);
  const render::Camera camera = resolve_camera(o.view, mesh);

  render::GlContext context(gl);
  std::unique_ptr<render::Renderer> renderer;
  try {
    if (ro.mode == render::Mode::kMultipass || ro.mode == render::Mode::kDecoupled)
      ro.groups = render::group_for_renderer(mesh, set, context, o.register_budget,
                                             o.clusters_per_pass, o.strategy);
    renderer =
        std::make_unique<render::Renderer>(mesh, &set, transfer ? &*transfer : nullptr, &probe, ro);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  renderer->set_background(background);
  const render::TimingSummary timing = render::measure(*renderer, camera, lighting, rotation, axis,
                                                       o.degrees_per_frame, o.frames, o.warmup);
  // One counted frame at the timed size; the timed frames draw as users' frames do.
  renderer->set_count_work(true);
  renderer->set_count_primitives(ro.mode == render::Mode::kMultipass);
  renderer->render(camera, lighting, rotation);
  const render::RenderStats counted = renderer->stats();
  renderer->set_count_work(false);
  renderer->set_count_primitives(false);
  const render::Camera image_camera = render::supersampled(camera, o.supersample);
  const double image_ms = renderer->render(image_camera, lighting, rotation).total_ms;
  const render::Image samples = renderer->read_image();
  const auto filter_start = std::chrono::steady_clock::now();
  const render::Image image = render::box_downsample(samples, o.supersample);
  const double downsample_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - filter_start)
          .count();
  render::write_exr(o.output, image);
  if (!o.png.empty()) render::write_png(o.png, image, o.view.exposure);
  const render::RenderStats& st = counted;
  if (!st.measured_triangles.empty() && st.measured_triangles != st.triangles_per_pass)
    throw std::runtime_error("GL counted " + count_list(st.measured_triangles) +
                             " triangles per pass but the grouping predicts " +
                             count_list(st.triangles_per_pass) + " (a renderer bug)");
  print_report(o, st, timing, image_ms, downsample_ms);
}

constexpr const char* kAbout =
    "Relight a compressed bake (.prtc) under a rotated probe, or show a surface light field "
    "(.slfc); write EXR/PNG and FPS";

}  // namespace cmd_render

Runner add_render_command(CLI::App& app) {
  return add_command<cmd_render::Options>(app, "render", cmd_render::kAbout, cmd_render::add_flags,
                                          cmd_render::run);
}

}  // namespace prtr_app
