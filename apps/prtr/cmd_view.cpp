// prtr view MESH --probe PROBE: interactive relighting in a browser. Bakes and compresses
// through the cache as relight does, then serves a page (viewer/src/page.cpp) that asks for
// frames rendered on demand by one OSMesa renderer (viewer/scene.h, viewer/server.h).
// prtr view X.slfc --probe PROBE serves a surface light field the same way
// (viewer/slf_scene.h): its lighting is baked, so the page orbits the camera only.
#include "bake_flags.h"
#include "commands.h"
#include "compress_flags.h"
#include "cpca/compressed_file.h"
#include "cpca/supercluster_strategy.h"
#include "flag_checks.h"
#include "gl_flags.h"
#include "mesh_flags.h"
#include "meshes/load.h"
#include "pipeline/pipeline.h"
#include "probes/load.h"
#include "progress_bar.h"
#include "prt/sh.h"
#include "prt/slf_directions.h"
#include "slf_input.h"
#include "supersample_flag.h"
#include "view_flags.h"
#include "viewer/scene.h"
#include "viewer/server.h"
#include "viewer/slf_scene.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace prtr_app {
using common::Json;
namespace fs = std::filesystem;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_view {

using viewer::SceneInfo;
using viewer::ServedInfo;
using viewer::ViewState;

struct Options {
  std::string mesh, probe, cache, mode = "decoupled", strategy = "greedy-refine";
  std::string slf_mesh;  // --mesh, for a .slfc only
  MeshFlags mesh_flags;
  BakeFlags bake;
  CompressFlags compress;
  ViewFlags view;
  viewer::ServerOptions server;
  GlFlags gl;
  int register_budget = 0;
  int supersample = kDefaultSupersample;
  bool quiet = false;
};

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh,
                  std::string("Mesh file (") + meshes::kMeshFormats +
                      "), or a surface light field (.slfc) from prtr slf")
      ->required();
  cmd->add_option("--probe", o.probe,
                  "Light probe (EXR/HDR); the page offers every *.exr/*.hdr in its folder (a "
                  ".slfc: the probe it was baked under, and only that one)")
      ->required();
  cmd->add_option("--mesh", o.slf_mesh,
                  "A .slfc's mesh (default: the path it records); MESH is the mesh otherwise");
  add_mesh_flags(cmd, o.mesh_flags);
  add_checked_option(
      cmd, "--mode", o.mode, "Initial rendering path",
      CLI::IsMember({"multipass", "singlepass", "decoupled", "cpu", "uncompressed"}));
  cmd->add_option("--strategy", o.strategy, "Initial super-cluster strategy")
      ->capture_default_str();
  add_checked_option(cmd, "--register-budget", o.register_budget,
                     "Initial vec4 registers per pass (0: what the GL context offers)",
                     integer_in(0, 1 << 20));
  add_compress_flags(cmd, o.compress, CompressFlagSet::kPipeline);
  add_bake_flags(cmd, o.bake);
  o.view.width = 960;  // the page's default size; it can ask for others
  o.view.height = 710;
  add_view_flags(cmd, o.view);
  add_supersample_flag(cmd, o.supersample,
                       "the page's still views (moving ones have one sample per pixel)", 4);
  add_gl_flags(cmd, o.gl);
  cmd->add_option("--cache", o.cache, "Cache directory (default $PRTR_CACHE or ~/.cache/prtr)");
  cmd->add_option("--host", o.server.host, "Address to listen on")->capture_default_str();
  add_checked_option(cmd, "--port", o.server.port, "Port to listen on (0: any free port)",
                     integer_in(0, 65535));
  cmd->add_flag("-q,--quiet", o.quiet, "No progress bars");
}

bool is_probe_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".exr" || ext == ".hdr";
}

// The probes the page may choose: the *.exr/*.hdr beside --probe, by name, --probe among them.
// Only this list is ever opened; requests name an index into it.
std::vector<fs::path> scan_probes(const fs::path& given, int& index) {
  const fs::path probe = given.lexically_normal();
  std::vector<fs::path> found;
  std::error_code ec;
  const fs::path dir = probe.has_parent_path() ? probe.parent_path() : fs::path(".");
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file(ec) && is_probe_file(entry.path()))
      found.push_back(entry.path().lexically_normal());
  if (std::find(found.begin(), found.end(), probe) == found.end()) found.push_back(probe);
  std::sort(found.begin(), found.end());
  index = int(std::find(found.begin(), found.end(), probe) - found.begin());
  return found;
}

Json info_json(const Options& o, const meshes::Mesh& mesh, const cpca::CompressedSet& set,
               const pipeline::CompressionSummary& summary, const SceneInfo& scene,
               const std::vector<fs::path>& probes, const ServedInfo& served) {
  Json names = Json::array();
  for (const fs::path& p : probes) names.push_back(p.filename().string());
  Json strategies = Json::array();
  for (const auto& s : cpca::supercluster_strategies()) strategies.push_back(std::string(s.name));
  const ViewState& d = served.defaults;
  return Json{{"kind", "prt"},
              {"mesh", fs::path(o.mesh).filename().string()},
              {"vertices", mesh.vertex_count()},
              {"triangles", mesh.triangle_count()},
              {"clusters", set.cluster_count},
              {"pcs", set.component_count},
              {"max_clusters", served.limits.max_clusters},
              {"max_pcs", served.limits.max_components},
              {"max_order", served.limits.max_order},
              {"order", set.order},
              {"average_se", summary.average_se},
              {"relative_error", summary.relative_error},
              {"gl_renderer", scene.gl_renderer},
              {"gl_version", scene.gl_version},
              {"llvmpipe_threads", scene.llvmpipe_threads},
              {"llvmpipe_threads_source", scene.llvmpipe_threads_source},
              {"default_register_budget", scene.default_register_budget},
              {"registers_per_cluster", scene.registers_per_cluster},
              {"still_samples", o.supersample},
              {"modes", render::kModeNames.names()},
              {"strategies", strategies},
              {"probes", names},
              {"defaults",
               {{"mode", render::kModeNames.name(d.mode)},
                {"strategy", d.strategy},
                {"probe", d.probe},
                {"exposure", d.exposure},
                {"width", d.width},
                {"height", d.height}}}};
}

ViewState initial_state(const Options& o, int probe) {
  try {
    cpca::find_supercluster_strategy(o.strategy);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--strategy: ") + e.what());
  }
  ViewState s;
  s.width = o.view.width;
  s.height = o.view.height;
  s.mode = render::kModeNames.parse(o.mode);
  s.strategy = o.strategy;
  s.register_budget = o.register_budget;
  s.probe = probe;
  s.exposure = o.view.exposure;
  return s;
}

// The flags a surface light field reads: its input, the camera and image, the GL backend and
// the server. Every other one (bake, compression, rendering path, environment axis, cache)
// describes PRT work that a .slfc has already had done, once, under its own settings.
const std::set<std::string>& slf_flags() {
  static const std::set<std::string> flags = {
      "MESH",        "--probe", "--mesh", "--crease-angle", "--width",    "--height",      "--eye",
      "--target",    "--up",    "--fov",  "--background",   "--exposure", "--supersample", "--gl",
      "--gl-device", "--host",  "--port", "--quiet",        "--help"};
  return flags;
}

Json slf_info_json(const Options& o, const SlfInput& in, const SceneInfo& scene,
                   const ViewState& d) {
  const pipeline::CompressedSlf& slf = in.slf;
  const std::string space(prt::kSlfDirectionSpaceNames.name(slf.bake.grid.space));
  return Json{{"kind", "slf"},
              {"slfc", fs::path(o.mesh).filename().string()},
              {"mesh", fs::path(in.mesh_path).filename().string()},
              {"vertices", in.mesh.vertex_count()},
              {"triangles", in.mesh.triangle_count()},
              {"clusters", slf.set.cluster_count},
              {"components", slf.set.component_count},
              {"texels", slf.bake.rows},
              {"atlas_width", slf.bake.atlas_width},
              {"atlas_height", slf.bake.atlas_height},
              {"directions", slf.bake.grid.directions()},
              {"azimuth", slf.bake.grid.azimuth},
              {"elevation", slf.bake.grid.elevation},
              {"direction_space", space},
              {"probe_name", slf.probe_name},
              {"probes", Json::array({fs::path(o.probe).filename().string()})},
              {"gl_renderer", scene.gl_renderer},
              {"gl_version", scene.gl_version},
              {"llvmpipe_threads", scene.llvmpipe_threads},
              {"llvmpipe_threads_source", scene.llvmpipe_threads_source},
              {"still_samples", o.supersample},
              {"defaults",
               {{"probe", 0}, {"exposure", d.exposure}, {"width", d.width}, {"height", d.height}}}};
}

// prtr view X.slfc: the light field under the probe it was baked under, the camera orbiting.
void run_slf(const Options& o, CLI::App* cmd) {
  for (const CLI::Option* option : cmd->get_options()) {
    const std::string name = option->get_name();
    if (option->count() > 0 && slf_flags().count(name) == 0)
      throw UsageError(name + " applies to meshes (PRT); " + o.mesh +
                       " is a surface light field, whose lighting and compression are baked "
                       "and which renders in one pass");
  }
  const render::Background background = resolve_background(o.view);
  const render::CameraPlacement placement = resolve_placement(o.view);
  const render::GlSelection gl = gl_selection(o.gl);
  const SlfInput in = load_slf_input(o.mesh, o.slf_mesh, o.mesh_flags, o.probe);
  resolve_camera(o.view, in.mesh);  // a bad --eye or --fov: exit 2 now
  const std::string name = fs::path(o.mesh).filename().string();
  viewer::SlfScene scene({&in.mesh, &in.model, &in.probe, name, placement, background, gl});
  ServedInfo served;
  served.defaults.width = o.view.width;
  served.defaults.height = o.view.height;
  served.defaults.exposure = o.view.exposure;
  served.limits.probe_count = 1;
  served.limits.cluster_count = in.slf.set.cluster_count;
  const auto first = scene.render(served.defaults);
  if (!first->request_error.empty()) throw UsageError(first->request_error);
  if (!first->server_error.empty()) throw std::runtime_error(first->server_error);
  served.info = slf_info_json(o, in, scene.info(), served.defaults);
  std::printf(
      "prtr view: %s, surface light field of %d cluster(s) x %d term(s), %llu texels, %d x %d "
      "directions; first frame %.0f ms\n",
      o.mesh.c_str(), int(in.slf.set.cluster_count), int(in.slf.set.component_count),
      static_cast<unsigned long long>(in.slf.bake.rows), in.slf.bake.grid.azimuth,
      in.slf.bake.grid.elevation, first->stats.render_ms);
  viewer::serve_view(scene, served, o.server);
}

void run(const Options& o, CLI::App* cmd) {
  if (is_slfc(o.mesh)) return run_slf(o, cmd);
  if (!o.slf_mesh.empty())
    throw UsageError("--mesh names a .slfc's mesh; " + o.mesh + " is the mesh here");
  const prt::BakeOptions bake = resolve_bake_flags(o.bake);
  const cpca::CompressOptions compress = resolve_compress_flags(o.compress);
  const render::Background background = resolve_background(o.view);
  const Eigen::Vector3d axis = resolve_axis(o.view);
  const render::CameraPlacement placement = resolve_placement(o.view);
  const render::GlSelection gl = gl_selection(o.gl);
  int probe_index = 0;
  const std::vector<fs::path> probes = scan_probes(o.probe, probe_index);
  ServedInfo served;
  served.defaults = initial_state(o, probe_index);
  const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
  resolve_camera(o.view, mesh);
  probes::load_probe(o.probe);  // fail before the long work
  const fs::path cache = o.cache.empty() ? pipeline::default_cache_dir() : fs::path(o.cache);
  const pipeline::Reporter reporter = stderr_reporter(o.quiet);
  const pipeline::CacheResult transfer = pipeline::cached_bake(mesh, o.mesh, bake, cache, reporter);
  const pipeline::CompressCacheResult compressed =
      pipeline::cached_compress(transfer.path, mesh, o.mesh, compress, cache, reporter);
  // Other clusters, PCs and SH orders from the page: the same cached pipeline, in the
  // background; another order bakes first (half the progress), then compresses.
  const auto make = [&](int clusters, int pcs, int order,
                        const std::function<void(double)>& progress) {
    prt::BakeOptions b = bake;
    b.order = order;
    cpca::CompressOptions c = compress;
    c.clusters = clusters;
    c.components = pcs;
    const bool baking = order != bake.order;
    pipeline::Reporter quiet;
    double base = 0.0, share = baking ? 0.5 : 1.0;
    quiet.progress = [&](const std::string&, std::uint64_t done, std::uint64_t total) {
      if (total > 0) progress(base + share * double(done) / double(total));
    };
    const fs::path bake_path =
        baking ? pipeline::cached_bake(mesh, o.mesh, b, cache, quiet).path : transfer.path;
    if (baking) base = 0.5;
    return viewer::Compression{
        cpca::read_compressed(
            pipeline::cached_compress(bake_path, mesh, o.mesh, c, cache, quiet).path),
        bake_path};
  };
  viewer::Compressions compressions({cpca::read_compressed(compressed.path), transfer.path}, make);
  const cpca::CompressedSet& set = compressions.launch();
  viewer::ViewScene scene({&mesh, &compressions, probes, placement, background, axis, gl});
  served.limits = {int(probes.size()), set.cluster_count, true};
  // The page may ask for up to 64 PCs; the compression refuses more than the data holds.
  served.limits.max_clusters = int(std::min<std::size_t>(mesh.vertex_count(), 65536));
  served.limits.max_components = 64;
  // Orders past 8 make bakes of gigabytes for a mesh like the bunny (order 10: 1.4 GB).
  served.limits.max_order = std::max(set.order, std::min(8, prt::kMaxOrder));
  served.limits.launch_order = set.order;
  served.limits.launch_components = set.component_count;
  served.limits.glossy = set.glossy();
  served.limits.max_register_budget = scene.info().default_register_budget;
  served.limits.registers_per_cluster = scene.info().registers_per_cluster;
  // The initial state renders once here, so a flag the renderer refuses exits 2 now.
  const auto first = scene.render(served.defaults);
  if (!first->request_error.empty()) throw UsageError(first->request_error);
  if (!first->server_error.empty()) throw std::runtime_error(first->server_error);
  served.info = info_json(o, mesh, set, compressed.summary, scene.info(), probes, served);
  std::printf("prtr view: %s, %d clusters x %d PCs, order %d; first frame %.0f ms\n",
              o.mesh.c_str(), set.cluster_count, set.component_count, set.order,
              first->stats.render_ms);
  viewer::serve_view(scene, served, o.server);
}

constexpr const char* kAbout =
    "Bake, compress (cached) and serve MESH under PROBE to a browser: drag to relight, with "
    "render modes, probes, overlays and live statistics; or orbit a surface light field (.slfc)";

}  // namespace cmd_view

Runner add_view_command(CLI::App& app) {
  return add_command<cmd_view::Options>(app, "view", cmd_view::kAbout, cmd_view::add_flags,
                                        cmd_view::run);
}

}  // namespace prtr_app
