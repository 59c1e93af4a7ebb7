// prtr bake MESH -o FILE: per-vertex SH transfer (shadow + interreflection passes).
#include "commands.h"

#include "meshes/load.h"
#include "progress_bar.h"
#include "prt/bake.h"
#include "prt/transfer_file.h"

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace prtr_app {
namespace {

// "0.5" (grey) or "0.5,0.4,0.3".
Eigen::Vector3f parse_albedo(const std::string& text) {
  std::vector<float> values;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      values.push_back(std::stof(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--albedo: '" + text + "' is not a number or R,G,B triple");
    }
  }
  if (values.size() == 1) return Eigen::Vector3f::Constant(values[0]);
  if (values.size() == 3) return {values[0], values[1], values[2]};
  throw UsageError("--albedo takes one value (grey) or three (R,G,B), got '" + text + "'");
}

}  // namespace

Runner add_bake_command(CLI::App& app) {
  struct Options {
    std::string mesh, output, kind = "glossy", material = "phong", albedo = "0.5";
    prt::BakeOptions bake;
    bool quiet = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "bake", "Bake per-vertex SH transfer (shadow and interreflection passes) to a .prtx file");
  cmd->add_option("MESH", opt->mesh, "Mesh file (OBJ, PLY, OFF, STL)")->required();
  cmd->add_option("-o,--output", opt->output, "Transfer file to write (.prtx)")->required();
  cmd->add_option("--kind", opt->kind, "diffuse: transfer vectors; glossy: transfer matrices")
      ->check(CLI::IsMember({"diffuse", "glossy"}))
      ->capture_default_str();
  cmd->add_option("--order", opt->bake.order, "SH order N (N^2 coefficients)")
      ->check(CLI::Range(1, 10))
      ->capture_default_str();
  cmd->add_option("--samples", opt->bake.samples, "Hemisphere directions per vertex")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  cmd->add_option("--bounces", opt->bake.bounces, "Interreflection passes (0: shadows only)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  cmd->add_option("--seed", opt->bake.seed, "Seed of the direction set")->capture_default_str();
  cmd->add_option("--material", opt->material, "Reflectance model")
      ->check(CLI::IsMember({"lambert", "phong", "cook-torrance"}))
      ->capture_default_str();
  cmd->add_option("--albedo", opt->albedo, "Diffuse albedo: one value (grey) or R,G,B")
      ->capture_default_str();
  cmd->add_option("--specular", opt->bake.material.specular,
                  "Specular reflectance (phong, cook-torrance)")
      ->capture_default_str();
  cmd->add_option("--exponent", opt->bake.material.exponent, "Phong exponent")
      ->capture_default_str();
  cmd->add_option("--roughness", opt->bake.material.roughness, "Cook-Torrance Beckmann roughness")
      ->capture_default_str();
  cmd->add_option("--f0", opt->bake.material.f0,
                  "Cook-Torrance Fresnel reflectance at normal incidence")
      ->capture_default_str();
  cmd->add_option("--ray-offset", opt->bake.ray_offset,
                  "Ray start offset along the normal, times the bounding-box diagonal")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress bar");

  return [opt, cmd] {
    Options& o = *opt;
    o.bake.kind = o.kind == "diffuse" ? prt::TransferKind::kDiffuse : prt::TransferKind::kGlossy;
    o.bake.material.kind = prt::parse_material(o.material);
    o.bake.material.albedo = parse_albedo(o.albedo);
    // A flag the chosen material never reads is a mistake worth reporting.
    const auto kind = o.bake.material.kind;
    auto unused = [&](const char* flag, bool used) {
      if (cmd->count(flag) && !used) {
        throw UsageError(std::string(flag) + " does not apply to --material " + o.material);
      }
    };
    unused("--exponent", kind == prt::MaterialKind::kPhong);
    unused("--roughness", kind == prt::MaterialKind::kCookTorrance);
    unused("--f0", kind == prt::MaterialKind::kCookTorrance);
    unused("--specular", kind != prt::MaterialKind::kLambert);
    if (kind == prt::MaterialKind::kLambert) o.bake.material.specular = 0.f;
    try {
      prt::validate(o.bake);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }

    meshes::LoadReport report;
    const meshes::Mesh mesh = meshes::load_mesh(o.mesh, {}, &report);
    const prt::BakeEstimate estimate = prt::estimate_bake(mesh, o.bake);
    const std::uint64_t available = prt::available_memory();
    if (available > 0 && estimate.bytes > available) {
      throw std::runtime_error("baking " + o.mesh + " needs about " + format_bytes(estimate.bytes) +
                               " but only " + format_bytes(available) +
                               " is available; lower --order or --samples, use --bounces 0, "
                               "or --kind diffuse");
    }
    if (!o.quiet) {
      std::fprintf(stderr,
                   "bake: %zu vertices, %s order %d, %d samples, %d bounce(s); about %s "
                   "of memory, %.1f M shadow rays, roughly %.0f s\n",
                   mesh.vertex_count(), o.kind.c_str(), o.bake.order, o.bake.samples,
                   o.bake.bounces, format_bytes(estimate.bytes).c_str(),
                   double(estimate.rays) / 1e6, estimate.seconds);
    }

    ProgressBar bar(o.quiet);
    o.bake.progress = [&bar](const prt::BakeProgress& p) {
      bar.update(p.pass == 0 ? "shadow pass" : "bounce " + std::to_string(p.pass), p.done, p.total);
    };
    prt::BakeStats stats;
    const prt::TransferSet set = prt::bake(mesh, o.bake, &stats);
    bar.finish();
    prt::write_transfer(o.output, set);

    const double rays = double(stats.rays_shadow + stats.rays_bounce);
    std::printf("baked       %s -> %s\n", o.mesh.c_str(), o.output.c_str());
    std::printf("transfer    %s, order %d, %d channel(s), %zu vertices, %s\n",
                prt::transfer_kind_name(set.kind), set.order, set.channels, mesh.vertex_count(),
                format_bytes(set.data.size() * sizeof(float)).c_str());
    std::printf("time        %.2f s total: %.2f s shadow, %.2f s bounces, %.2f s BRDF matrix\n",
                stats.seconds_total, stats.seconds_shadow, stats.seconds_bounces,
                stats.seconds_brdf);
    std::printf("rays        %.1f M (%.1f M shadow, %.1f M bounce), %.1f M rays/s\n", rays / 1e6,
                double(stats.rays_shadow) / 1e6, double(stats.rays_bounce) / 1e6,
                rays / 1e6 / (stats.seconds_shadow + stats.seconds_bounces));
    std::printf("occluded    %.1f%% of shadow rays\n", 100.0 * stats.occluded_fraction);
  };
}

}  // namespace prtr_app
