// prtr probe FILE: load an environment map, print its facts and its SH projection.
#include "commands.h"
#include "flag_checks.h"

#include "probes/load.h"
#include "prt/projection.h"
#include "prt/sh.h"

#include <chrono>
#include <cstdio>
#include <map>
#include <string>

namespace prtr_app {

// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_probe {

void print_coefficients(const prt::ShLighting& sh, int order) {
  std::printf("%4s %4s %14s %14s %14s\n", "l", "m", "R", "G", "B");
  for (int l = 0; l < order; ++l) {
    for (int m = -l; m <= l; ++m) {
      const int i = prt::sh_index(l, m);
      std::printf("%4d %4d %14.6g %14.6g %14.6g\n", l, m, sh(i, 0), sh(i, 1), sh(i, 2));
    }
  }
}

// What was read, what loading made of it, and the projection (a cube map's against its
// lat-long resampling, which the other commands light with).
void print_report(const probes::LoadReport& report, const probes::Probe& probe,
                  const prt::ShLighting& sh, int order, double ms) {
  const probes::Rgb peak = probe.max_texel();
  const probes::Rgb mean = probe.mean_radiance();
  std::printf("probe       %s (%s)\n", report.path.c_str(), report.format.c_str());
  std::printf("file        %d x %d, %d channels, %s layout%s\n", report.file_width,
              report.file_height, report.file_channels, probes::layout_name(report.layout),
              report.layout != probes::Layout::kCross        ? ""
              : report.cross == probes::CrossKind::kVertical ? " (vertical)"
                                                             : " (horizontal)");
  std::printf("lat-long    %d x %d\n", probe.width(), probe.height());
  std::printf("clamped     %zu negative texels\n", report.negative_texels_clamped);
  std::printf("peak        (%.6g, %.6g, %.6g)\n", peak.x(), peak.y(), peak.z());
  std::printf("mean        (%.6g, %.6g, %.6g)  (solid-angle weighted radiance)\n", mean.x(),
              mean.y(), mean.z());
  std::printf("projection  order %d, %d coefficients, %.1f ms%s\n", order, prt::sh_count(order), ms,
              report.cube ? ", cube texels with exact solid angles" : "");
  if (report.cube) {
    const double gap = (prt::project_latlong(probe, order) - sh).cwiseAbs().maxCoeff();
    std::printf("resampled   lat-long projection differs by at most %.3g\n", gap);
  }
}

}  // namespace cmd_probe

Runner add_probe_command(CLI::App& app) {
  using namespace cmd_probe;
  struct Options {
    std::string path;
    int order = 6;
    std::string layout = "auto";
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "probe",
      "Load an HDR environment map (lat-long, angular or cube map) and print its SH lighting");
  cmd->add_option("PROBE", opt->path,
                  "Environment map (EXR, HDR, ...); for six cube faces a folder holding "
                  "px nx py ny pz nz, or a name with {face} in it")
      ->required();
  add_checked_option(cmd, "--order", opt->order, "SH order N (bands 0..N-1, N^2 coefficients)",
                     integer_in(prt::kMinOrder, prt::kMaxOrder));
  cmd->add_option("--layout", opt->layout,
                  "Map layout; auto: 2:1 lat-long, 1:1 angular, 4:3 / 3:4 cube cross, a folder "
                  "or {face} name six cube faces")
      ->check(CLI::IsMember({"auto", "latlong", "angular", "cross", "faces"}))
      ->capture_default_str();

  return [opt] {
    static const std::map<std::string, probes::Layout> kLayouts = {
        {"auto", probes::Layout::kAuto},
        {"latlong", probes::Layout::kLatLong},
        {"angular", probes::Layout::kAngular},
        {"cross", probes::Layout::kCross},
        {"faces", probes::Layout::kFaces}};
    probes::LoadOptions options;
    options.layout = kLayouts.at(opt->layout);
    probes::LoadReport report;
    const probes::Probe probe = probes::load_probe(opt->path, options, &report);

    // A cube map is projected over its own texels with their exact solid angles (as in every
    // command); the projection of its lat-long resampling is shown beside it.
    const auto start = std::chrono::steady_clock::now();
    const prt::ShLighting sh = prt::project(probe, opt->order);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

    print_report(report, probe, sh, opt->order, ms);
    print_coefficients(sh, opt->order);
  };
}

}  // namespace prtr_app
