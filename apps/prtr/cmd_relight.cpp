// prtr relight MESH --probe PROBE: the whole pipeline in one command. Bakes and compresses
// through the cache (a second run with the same inputs skips both), then renders a frame
// sequence while the environment turns about an axis (SH rotation per frame, no
// re-projection), or with --camera-orbit while the camera turns about the mesh under fixed
// lighting, writing EXR frames, PNG previews, a contact sheet, an animated GIF and, when
// ffmpeg is installed, an MP4. --kind slf makes a surface light field instead (prtr slf's
// cached pipeline) and orbits the camera around it: its lighting is baked.
#include "animation.h"
#include "bake_flags.h"
#include "commands.h"
#include "common/work_queue.h"
#include "compress_flags.h"
#include "contact_sheet.h"
#include "cpca/compressed_file.h"
#include "flag_checks.h"
#include "gl_flags.h"
#include "mesh_flags.h"
#include "meshes/load.h"
#include "pipeline/pipeline.h"
#include "pipeline/slf.h"
#include "probes/load.h"
#include "progress_bar.h"
#include "prt/projection.h"
#include "prt/sh_rotation.h"
#include "render/gif.h"
#include "render/gl_context.h"
#include "render/image.h"
#include "render/pass_grouping.h"
#include "render/renderer.h"
#include "render/slf_renderer.h"
#include "render/supersample.h"
#include "slf_flags.h"
#include "slf_input.h"
#include "supersample_flag.h"
#include "view_flags.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

namespace prtr_app {
namespace fs = std::filesystem;
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_relight {

std::string frame_name(int index, const char* extension) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%04d.%s", index, extension);
  return buf;
}

// Frames of an earlier, longer run would mix into the sequence (and the video): remove
// files named exactly like ours, nothing else.
void remove_old_frames(const fs::path& dir) {
  static const std::regex pattern("frame_[0-9]{4}\\.(exr|png)");
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (std::regex_match(entry.path().filename().string(), pattern)) fs::remove(entry.path(), ec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Options {
  std::string mesh, probe, out = "out/relight", cache, mode = "decoupled";
  std::string strategy = "greedy-refine";
  BakeFlags bake;
  ViewFlags view;
  CompressFlags compress;
  GlFlags gl;
  MeshFlags mesh_flags;
  SlfFlags slf;  // --kind slf
  int frames = 24, columns = 6, thumbnail = 320, fps = 24, register_budget = 0, gif_width = 640;
  int supersample = kDefaultSupersample;
  double degrees = 360.0;
  bool quiet = false, no_video = false, camera_orbit = false;
  std::string exr_pixels = "half", accumulation = "auto", constants = "auto";
  std::string slf_shading = "auto";  // --kind slf
};

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("MESH", o.mesh, std::string("Mesh file: ") + meshes::kMeshFormats)->required();
  cmd->add_option("--probe", o.probe, "Light probe (lat-long or angular EXR/HDR)")->required();
  cmd->add_option("--out", o.out, "Output directory")->capture_default_str();
  add_checked_option(cmd, "--frames", o.frames, "Frames in the sequence", integer_in(1, 100000));
  add_checked_option(cmd, "--degrees", o.degrees,
                     "Total rotation over the sequence: the environment's, or the camera's "
                     "with --camera-orbit",
                     angle_degrees());
  cmd->add_flag("--camera-orbit", o.camera_orbit,
                "The camera turns about --axis through the mesh's centre while the lighting "
                "stays fixed (instead of the environment turning); needed by --kind slf");
  add_checked_option(cmd, "--mode", o.mode, "Rendering path (render/renderer.h)",
                     CLI::IsMember({"multipass", "singlepass", "decoupled", "cpu"}));
  cmd->add_option("--strategy", o.strategy, "Super-cluster strategy for multipass/decoupled")
      ->capture_default_str();
  cmd->add_option("--register-budget", o.register_budget,
                  "vec4 registers per pass (0: what the GL context offers; thesis GPU: 256)")
      ->check(integer_in(0, 1 << 20))
      ->capture_default_str();
  add_compress_flags(cmd, o.compress, CompressFlagSet::kPipeline);
  add_bake_flags(cmd, o.bake, true);
  add_slf_flags(cmd, o.slf, "--slf-samples");
  add_checked_option(cmd, "--slf-shading", o.slf_shading,
                     "--kind slf: where the reconstruction runs (render/slf_renderer.h; auto: "
                     "per frame, by cost)",
                     CLI::IsMember(render::kSlfShadingNames.names()));
  add_mesh_flags(cmd, o.mesh_flags);
  add_view_flags(cmd, o.view);
  add_supersample_flag(cmd, o.supersample);
  add_gl_flags(cmd, o.gl);
  add_accumulation_flag(cmd, o.accumulation);
  add_constants_flag(cmd, o.constants);
  cmd->add_option("--cache", o.cache, "Cache directory (default $PRTR_CACHE or ~/.cache/prtr)");
  add_checked_option(cmd, "--columns", o.columns, "Contact sheet columns", integer_in(1, 64));
  add_checked_option(cmd, "--thumbnail", o.thumbnail, "Contact sheet thumbnail width (pixels)",
                     integer_in(16, 4096));
  add_checked_option(cmd, "--fps", o.fps, "Video frame rate", integer_in(1, 240));
  add_checked_option(cmd, "--gif-width", o.gif_width,
                     "Width of the animated GIF preview in pixels (0: the frames' own size)",
                     integer_in(0, 65535));
  add_checked_option(cmd, "--exr-pixels", o.exr_pixels,
                     "EXR frames as half floats (PIZ, what renderers write for sequences) or "
                     "32-bit floats (ZIP, as prtr render writes)",
                     CLI::IsMember({"half", "float"}));
  cmd->add_flag("--no-video", o.no_video, "Do not encode the MP4 (the GIF is always written)");
  cmd->add_flag("-q,--quiet", o.quiet, "No progress bars");
}

// Usage errors the flags alone decide, before anything is read.
void check_sizes(const prt::BakeOptions& bake, const cpca::CompressOptions& compress) {
  const int n = bake.order * bake.order;
  const std::size_t dimension = std::size_t(bake.material.channels()) * std::size_t(n) *
                                std::size_t(bake.kind == prt::TransferKind::kGlossy ? n : 1);
  if (std::size_t(compress.components) >= dimension)
    throw UsageError("--pcs " + std::to_string(compress.components) +
                     " must be below the transfer dimension " + std::to_string(dimension) +
                     " (order " + std::to_string(bake.order) + ")");
}

void make_output_directory(const std::string& out) {
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec)
    throw std::runtime_error("output directory " + out + " cannot be created (" + ec.message() +
                             "); choose another --out");
}

// Bake and compress through the cache, reporting hits and times; the compressed set's path.
fs::path bake_and_compress(const Options& o, const meshes::Mesh& mesh, const prt::BakeOptions& bake,
                           const cpca::CompressOptions& compress) {
  const fs::path cache = o.cache.empty() ? pipeline::default_cache_dir() : fs::path(o.cache);
  const pipeline::Reporter reporter = stderr_reporter(o.quiet);
  const pipeline::CachedPair r =
      pipeline::cached_bake_and_compress(mesh, o.mesh, bake, compress, cache, reporter);
  std::printf("bake        %s %s (%.1f s)\n", r.transfer.hit ? "cached" : "baked",
              r.transfer.path.string().c_str(), r.bake_seconds);
  std::printf("compress    %s %s (%.1f s)\n", r.compressed.hit ? "cached" : "compressed",
              r.compressed.path.string().c_str(), r.compress_seconds);
  return r.compressed.path;
}

std::unique_ptr<render::Renderer> make_renderer(const Options& o, const meshes::Mesh& mesh,
                                                const cpca::CompressedSet& set,
                                                const probes::Probe& probe,
                                                const render::GlContext& context) {
  render::RendererOptions ro;
  ro.mode = render::kModeNames.parse(o.mode);
  ro.accumulation = render::kAccumulationNames.parse(o.accumulation);
  ro.constants = render::kConstantsNames.parse(o.constants);
  ro.register_budget = o.register_budget;
  try {
    if (ro.mode == render::Mode::kMultipass || ro.mode == render::Mode::kDecoupled)
      ro.groups = render::group_for_renderer(mesh, set, context, o.register_budget, 0, o.strategy);
    auto renderer = std::make_unique<render::Renderer>(mesh, &set, nullptr, &probe, ro);
    renderer->set_background(resolve_background(o.view));
    return renderer;
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

// frame_ms, gl_ms and cpu_ms are the renderer's (at the supersampled size); downsample_ms
// is the anti-aliasing filter on the CPU after it, kept apart so FPS means what it always did.
struct FrameTimes {
  std::vector<double> frame_ms, gl_ms, cpu_ms, downsample_ms;
  double seconds = 0;  // with EXR/PNG output
};

// What the frames leave besides their files: contact-sheet thumbnails and GIF frames.
struct Previews {
  std::vector<render::Image> thumbnails;
  std::vector<render::Rgb8Image> gif;  // every gif_stride-th frame, gif_width wide
  int gif_stride = 1, gif_width = 0;
};

// GIF frames are kept in memory until the palette of the whole sequence is known: past this
// much, the GIF shows every k-th frame instead (a preview, not the sequence itself).
constexpr double kGifBudgetBytes = 512.0 * 1024 * 1024;

int gif_width(const Options& o, const render::Camera& camera) {
  return o.gif_width == 0 ? camera.width : std::min(o.gif_width, camera.width);
}

Previews make_previews(const Options& o, const render::Camera& camera) {
  Previews p;
  const int width = p.gif_width = gif_width(o, camera);
  const double height = std::max(1.0, std::round(double(camera.height) * width / camera.width));
  const double bytes = double(width) * height * 3.0 * double(o.frames);
  p.gif_stride = int(std::ceil(std::max(1.0, bytes / kGifBudgetBytes)));
  p.thumbnails.resize(std::size_t(o.frames));
  p.gif.resize(std::size_t((o.frames + p.gif_stride - 1) / p.gif_stride));
  return p;
}

// One frame's files and previews, on a writer thread: every frame writes its own files and
// its own slots of `previews`, so writers share nothing.
void write_frame(const Options& o, int f, const render::Image& image, Previews& previews) {
  render::write_exr(fs::path(o.out) / frame_name(f, "exr"), image,
                    o.exr_pixels == "half" ? render::ExrPixels::kHalf : render::ExrPixels::kFloat);
  render::write_png(fs::path(o.out) / frame_name(f, "png"), image, o.view.exposure);
  previews.thumbnails[std::size_t(f)] = downscale(image, o.thumbnail);
  if (f % previews.gif_stride == 0) {
    const int gif_w = previews.gif_width;
    const render::Image small = gif_w == image.width ? image : downscale(image, gif_w);
    previews.gif[std::size_t(f / previews.gif_stride)] = {
        small.width, small.height, render::tone_map_rgb8(small, o.view.exposure)};
  }
}

// Writers for the frames: image encoding (EXR's PIZ or ZIP, PNG's deflate) costs about the
// render's time, so it overlaps with rendering on every core.
int writer_threads() {
  return std::clamp(int(std::thread::hardware_concurrency()), 2, 8);
}

// One frame of the sequence at the supersampled size, drawn; then its samples, read.
struct FrameSource {
  std::function<render::FrameTiming(int frame)> draw;
  std::function<void(render::Image& samples)> read;
};

// Frame f's angle: --degrees over the sequence, the last frame one step short of it (so a
// full turn loops).
double frame_radians(const Options& o, int f) {
  return o.degrees * double(f) / double(o.frames) * std::numbers::pi / 180.0;
}

// The sequence: EXR and PNG per frame, written while the next frames render. The source
// draws at the supersampled size; each frame is box-filtered down to the requested size
// before it is queued.
FrameTimes render_frames(const Options& o, const FrameSource& source, Previews& previews) {
  for (int i = 0; i < 2; ++i) source.draw(0);  // warm-up
  remove_old_frames(o.out);
  ProgressBar bar(o.quiet);
  FrameTimes times;
  times.downsample_ms.resize(std::size_t(o.frames));
  const auto start = Clock::now();
  // Samples are read into one buffer and box-filtered here, so only frames of the output
  // size (19 MB at 1280 x 948) wait for the writers, two at most.
  common::WorkQueue writers(writer_threads(), 2);
  render::Image samples;
  for (int f = 0; f < o.frames; ++f) {
    bar.update("rendering frames", std::uint64_t(f), std::uint64_t(o.frames));
    const render::FrameTiming t = source.draw(f);
    times.frame_ms.push_back(t.total_ms);
    times.gl_ms.push_back(t.gl_ms);
    times.cpu_ms.push_back(t.cpu_ms);
    source.read(samples);
    const auto filter_start = Clock::now();
    auto image = std::make_shared<const render::Image>(
        o.supersample == 1 ? samples : render::box_downsample(samples, o.supersample));
    times.downsample_ms[std::size_t(f)] = 1000.0 * seconds_since(filter_start);
    writers.submit([&o, f, image, &previews] { write_frame(o, f, *image, previews); });
  }
  writers.finish();
  bar.finish();
  times.seconds = seconds_since(start);
  return times;
}

// Always the GIF; the MP4 too unless --no-video. What to print on the "animation" line.
std::string make_animations(const Options& o, const Previews& previews) {
  const fs::path gif = fs::path(o.out) / "relight.gif";
  render::write_gif(gif, previews.gif, double(o.fps) / previews.gif_stride);
  if (o.no_video) return gif.string() + "; MP4 skipped (--no-video)";
  const fs::path mp4 = fs::path(o.out) / "relight.mp4";
  switch (write_mp4(o.out, o.fps, mp4)) {
    case VideoResult::kWritten:
      return gif.string() + ", " + mp4.string();
    case VideoResult::kNoFfmpeg:
      return gif.string() + "; no MP4: ffmpeg is not installed (apt-get install ffmpeg)";
    case VideoResult::kFailed:
      break;
  }
  return gif.string() + "; no MP4: ffmpeg reported an error";
}

// The sequence's motion, as the "motion" line says it.
std::string motion(const Options& o) {
  char degrees[64];
  std::snprintf(degrees, sizeof degrees, " %g degrees about (", o.degrees);
  std::string text = o.camera_orbit ? "camera orbits the mesh's centre," : "environment turns";
  text += degrees;
  text += o.view.axis;
  text += ") over ";
  text += std::to_string(o.frames);
  text += " frames";
  return text;
}

// `render_line`: what drew the frames (the "render" line's text).
void print_summary(const Options& o, const std::string& render_line, const render::Camera& camera,
                   const FrameTimes& t, const std::string& video, const fs::path& sheet,
                   double total_s) {
  std::printf("render      %s, %d x %d (%d x %d samples per pixel: %d x %d rendered)\n",
              render_line.c_str(), camera.width, camera.height, o.supersample, o.supersample,
              camera.width * o.supersample, camera.height * o.supersample);
  std::printf("motion      %s\n", motion(o).c_str());
  std::printf(
      "frames      %d in %s: %.2f ms per frame median (%.1f FPS; CPU update %.2f ms, "
      "GL %.2f ms), %.2f s with EXR/PNG output\n",
      o.frames, o.out.c_str(), median(t.frame_ms), 1000.0 / median(t.frame_ms), median(t.cpu_ms),
      median(t.gl_ms), t.seconds);
  std::printf("anti-alias  %.2f ms per frame median to box-filter %d x %d samples per pixel\n",
              median(t.downsample_ms), o.supersample, o.supersample);
  std::printf("animation   %s\n", video.c_str());
  std::printf("total       %.1f s\n", total_s);
  std::printf("contact sheet: %s\n", sheet.string().c_str());
}

// The frames through `source`, then the contact sheet, the animations and the summary.
void render_outputs(const Options& o, const render::Camera& camera, const FrameSource& source,
                    const std::string& render_line, Clock::time_point start) {
  Previews previews = make_previews(o, camera);
  const FrameTimes times = render_frames(o, source, previews);
  const fs::path sheet = fs::path(o.out) / "contact_sheet.png";
  render::write_png(sheet, tile(previews.thumbnails, o.columns), o.view.exposure);
  const std::string video = make_animations(o, previews);
  print_summary(o, render_line, camera, times, video, sheet, seconds_since(start));
}

// Flags of one kind given with the other: usage errors naming the flag.
void check_kind_flags(const Options& o, const CLI::App* cmd) {
  const bool slf = o.bake.kind == "slf";
  if (slf) {
    for (const char* flag : {"--mode", "--strategy", "--register-budget", "--accumulation",
                             "--constants", "--order", "--samples", "--view-fit", "--ray-offset"})
      if (cmd->count(flag))
        throw UsageError(std::string(flag) +
                         " applies to PRT (--kind diffuse or glossy); a surface light field "
                         "(--kind slf) renders in one pass from its own bake (atlas size: "
                         "--slf-samples)");
    if (!o.camera_orbit)
      throw UsageError(
          "--kind slf needs --camera-orbit: a surface light field's lighting is baked, so "
          "the environment cannot turn; the camera orbits the mesh instead");
  } else {
    for (const char* flag : {"--slf-samples", "--charts", "--directions", "--spp", "--slf-shading"})
      if (cmd->count(flag))
        throw UsageError(std::string(flag) + " applies to --kind slf (a surface light field)");
  }
}

// --kind slf: prtr slf's pipeline (the bake cached as prtr slf caches it), then the camera's
// orbit drawn by the one-pass SLF renderer, with the probe as the unturned background.
void run_slf(const Options& o, Clock::time_point start) {
  pipeline::SlfSettings settings;
  resolve_slf_flags(o.slf, settings);
  settings.bake.bounces = o.bake.bake.bounces;
  settings.bake.seed = o.bake.bake.seed;
  settings.bake.material = resolve_material_flags(o.bake.material);
  settings.compress = resolve_compress_flags(o.compress);
  check_slf_settings(settings);
  const Eigen::Vector3d axis = resolve_axis(o.view);
  const render::Background background = resolve_background(o.view);
  const render::GlSelection gl = gl_selection(o.gl);
  const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
  const render::Camera camera = resolve_camera(o.view, mesh);
  const probes::Probe probe = probes::load_probe(o.probe);
  make_output_directory(o.out);
  const fs::path cache = o.cache.empty() ? pipeline::default_cache_dir() : fs::path(o.cache);
  pipeline::SlfRun r;
  try {
    r = pipeline::make_slf(mesh, o.mesh, probe, fs::path(o.probe).filename().string(), settings,
                           cache, stderr_reporter(o.quiet));
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());  // an atlas too small for the mesh, too many clusters
  }
  std::printf("bake        %s %s (%.1f s)\n", r.bake_cached ? "cached" : "baked",
              r.bake_path.string().c_str(), r.bake_seconds);
  std::printf(
      "compress    compressed %d cluster(s), %d PC(s): ratio %.1f, RMS error %.3g%% (%.1f s)\n",
      r.slf.set.cluster_count, r.slf.set.component_count, r.ratio, 100 * r.relative_rms_error,
      r.compress_seconds);
  const render::SlfModel model = slf_render_model(mesh, r.slf);

  render::GlContext context(gl);
  render::SlfRendererOptions ro;
  ro.shading = render::kSlfShadingNames.parse(o.slf_shading);
  render::SlfRenderer renderer(model, &probe, ro);
  renderer.set_background(background);
  const render::Camera big = render::supersampled(camera, o.supersample);
  const Eigen::Vector3d centre = mesh_centre(mesh);
  const FrameSource source{
      [&](int f) { return renderer.render(orbit_camera(big, centre, axis, frame_radians(o, f))); },
      [&](render::Image& samples) { renderer.read_image(samples); }};
  char line[200];
  std::snprintf(line, sizeof line, "slf, %s shading, %d x %d texels, %d x %d directions",
                render::kSlfShadingNames.name(renderer.options().shading), model.map_width,
                model.map_height, model.grid.azimuth, model.grid.elevation);
  render_outputs(o, camera, source, line, start);
}

void run(const Options& o, CLI::App* cmd) {
  const auto start = Clock::now();
  check_kind_flags(o, cmd);
  if (o.bake.kind == "slf") return run_slf(o, start);
  const prt::BakeOptions bake = resolve_bake_flags(o.bake);
  const cpca::CompressOptions compress = resolve_compress_flags(o.compress);
  const Eigen::Vector3d axis = resolve_axis(o.view);
  resolve_background(o.view);
  const render::GlSelection gl = gl_selection(o.gl);
  check_sizes(bake, compress);
  const meshes::Mesh mesh = meshes::load_mesh(o.mesh, load_options(o.mesh_flags));
  if (std::size_t(compress.clusters) > mesh.vertex_count())
    throw UsageError("--clusters " + std::to_string(compress.clusters) + " exceeds the " +
                     std::to_string(mesh.vertex_count()) + " vertices of " + o.mesh);
  const render::Camera camera = resolve_camera(o.view, mesh);
  const probes::Probe probe = probes::load_probe(o.probe);  // fail before the long work
  make_output_directory(o.out);
  const cpca::CompressedSet set = cpca::read_compressed(bake_and_compress(o, mesh, bake, compress));
  const prt::ShLighting lighting = prt::project(probe, set.order);
  render::GlContext context(gl);
  const auto renderer = make_renderer(o, mesh, set, probe, context);
  const render::Camera big = render::supersampled(camera, o.supersample);
  const Eigen::Vector3d centre = mesh_centre(mesh);
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  const FrameSource source{[&](int f) {
                             const double angle = frame_radians(o, f);
                             if (o.camera_orbit)
                               return renderer->render(orbit_camera(big, centre, axis, angle),
                                                       lighting, identity);
                             return renderer->render(big, lighting, prt::axis_angle(axis, angle));
                           },
                           [&](render::Image& samples) { renderer->read_image(samples); }};
  // Drawn once before the frames, for the statistics the render line reports.
  source.draw(0);
  const render::RenderStats st = renderer->stats();
  char line[200];
  std::snprintf(line, sizeof line, "%s, %d pass(es), average overdraw %.3f", o.mode.c_str(),
                st.passes, st.average_overdraw);
  render_outputs(o, camera, source, line, start);
}

constexpr const char* kAbout =
    "Bake, compress (cached) and render MESH under PROBE as it rotates (or as the camera "
    "orbits; --kind slf: a surface light field): EXR frames, PNG previews, a contact sheet, an "
    "animated GIF and an MP4 (ffmpeg)";

}  // namespace cmd_relight

Runner add_relight_command(CLI::App& app) {
  return add_command<cmd_relight::Options>(app, "relight", cmd_relight::kAbout,
                                           cmd_relight::add_flags, cmd_relight::run);
}

}  // namespace prtr_app
