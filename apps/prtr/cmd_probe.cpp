// prtr probe FILE: load an environment map, print its facts and its SH projection.
#include "commands.h"

#include "probes/load.h"
#include "prt/projection.h"
#include "prt/sh.h"

#include <chrono>
#include <cstdio>
#include <string>

namespace prtr_app {

Runner add_probe_command(CLI::App& app) {
  struct Options {
    std::string path;
    int order = 6;
    std::string layout = "auto";
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "probe", "Load an HDR environment map (lat-long or angular) and print its SH lighting");
  cmd->add_option("PROBE", opt->path, "Environment map (EXR, HDR, ...)")->required();
  cmd->add_option("--order", opt->order, "SH order N (bands 0..N-1, N^2 coefficients)")
      ->check(CLI::Range(prt::kMinOrder, prt::kMaxOrder))
      ->capture_default_str();
  cmd->add_option("--layout", opt->layout, "Map layout")
      ->check(CLI::IsMember({"auto", "latlong", "angular"}))
      ->capture_default_str();

  return [opt] {
    probes::LoadOptions options;
    if (opt->layout == "latlong") options.layout = probes::Layout::kLatLong;
    if (opt->layout == "angular") options.layout = probes::Layout::kAngular;
    probes::LoadReport report;
    const probes::Probe probe = probes::load_probe(opt->path, options, &report);

    const auto start = std::chrono::steady_clock::now();
    const prt::ShLighting sh = prt::project(probe, opt->order);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

    const probes::Rgb peak = probe.max_texel();
    const probes::Rgb mean = probe.mean_radiance();
    std::printf("probe       %s (%s)\n", report.path.c_str(), report.format.c_str());
    std::printf("file        %d x %d, %d channels, %s layout\n", report.file_width,
                report.file_height, report.file_channels, probes::layout_name(report.layout));
    std::printf("lat-long    %d x %d\n", probe.width(), probe.height());
    std::printf("clamped     %zu negative texels\n", report.negative_texels_clamped);
    std::printf("peak        (%.6g, %.6g, %.6g)\n", peak.x(), peak.y(), peak.z());
    std::printf("mean        (%.6g, %.6g, %.6g)  (solid-angle weighted radiance)\n", mean.x(),
                mean.y(), mean.z());
    std::printf("projection  order %d, %d coefficients, %.1f ms\n", opt->order,
                prt::sh_count(opt->order), ms);
    std::printf("%4s %4s %14s %14s %14s\n", "l", "m", "R", "G", "B");
    for (int l = 0; l < opt->order; ++l) {
      for (int m = -l; m <= l; ++m) {
        const int i = prt::sh_index(l, m);
        std::printf("%4d %4d %14.6g %14.6g %14.6g\n", l, m, sh(i, 0), sh(i, 1), sh(i, 2));
      }
    }
  };
}

}  // namespace prtr_app
