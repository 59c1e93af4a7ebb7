#include "bake_flags.h"

#include "commands.h"
#include "flag_checks.h"

#include <vector>

namespace prtr_app {
namespace {

// "0.5" (grey) or "0.5,0.4,0.3".
Eigen::Vector3f parse_albedo(const std::string& text) {
  const auto parsed = parse_number_list(text);
  if (!parsed) throw UsageError("--albedo: '" + text + "' is not a number or R,G,B triple");
  const std::vector<float> values(parsed->begin(), parsed->end());
  if (values.size() == 1) return Eigen::Vector3f::Constant(values[0]);
  if (values.size() == 3) return {values[0], values[1], values[2]};
  throw UsageError("--albedo takes one value (grey) or three (R,G,B), got '" + text + "'");
}

}  // namespace

void add_bake_flags(CLI::App* cmd, BakeFlags& f, bool with_slf) {
  f.command = cmd;
  if (with_slf)
    cmd->add_option("--kind", f.kind,
                    "diffuse: transfer vectors; glossy: transfer matrices; slf: a surface light "
                    "field (fixed lighting, prtr slf's pipeline)")
        ->check(CLI::IsMember({"diffuse", "glossy", "slf"}))
        ->capture_default_str();
  else
    cmd->add_option("--kind", f.kind, "diffuse: transfer vectors; glossy: transfer matrices")
        ->check(CLI::IsMember({"diffuse", "glossy"}))
        ->capture_default_str();
  add_checked_option(cmd, "--order", f.bake.order, "SH order N (N^2 coefficients)",
                     integer_in(1, 10));
  add_checked_option(cmd, "--samples", f.bake.samples, "Hemisphere directions per vertex",
                     integer_in(1, 65536));
  add_checked_option(cmd, "--bounces", f.bake.bounces, "Interreflection passes (0: shadows only)",
                     integer_in(0, 16));
  add_checked_option(cmd, "--seed", f.bake.seed, "Seed of the direction set", unsigned_integer());
  add_material_flags(cmd, f.material);
  cmd->add_option("--view-fit", f.view_fit,
                  "Glossy: how the view side fits exit radiance; hemisphere is the thesis's "
                  "projection (docs/ARCHITECTURE.md, \"The view side\")")
      ->check(CLI::IsMember({"least-squares", "even", "hemisphere"}))
      ->capture_default_str();
  add_checked_option(
      cmd, "--ray-offset", f.bake.ray_offset,
      "Rays start a tenth of this x the bbox diagonal into the face they leave through",
      number_in(0, 0.01));
}

void add_material_flags(CLI::App* cmd, MaterialFlags& f) {
  f.command = cmd;
  add_checked_option(cmd, "--material", f.material, "Reflectance model",
                     CLI::IsMember({"lambert", "phong", "cook-torrance"}));
  cmd->add_option("--albedo", f.albedo, "Diffuse albedo: one value (grey) or R,G,B")
      ->capture_default_str();
  add_checked_option(cmd, "--specular", f.values.specular,
                     "Specular reflectance (phong, cook-torrance)", number_in(0, 1));
  add_checked_option(cmd, "--exponent", f.values.exponent, "Phong exponent", number_in(0, 10000));
  // (0, 1]: number_in takes the closed range; Material::validate refuses 0 by name.
  add_checked_option(cmd, "--roughness", f.values.roughness, "Cook-Torrance Beckmann roughness",
                     number_in(0, 1));
  add_checked_option(cmd, "--f0", f.values.f0,
                     "Cook-Torrance Fresnel reflectance at normal incidence", number_in(0, 1));
  add_checked_option(
      cmd, "--masking", f.masking,
      "Cook-Torrance masking-shadowing: smith (height-correlated) or v-groove (the thesis's)",
      CLI::IsMember({"smith", "v-groove"}));
}

prt::Material resolve_material_flags(const MaterialFlags& f) {
  prt::Material m = f.values;
  m.kind = prt::kMaterialNames.parse(f.material);
  m.albedo = parse_albedo(f.albedo);
  m.masking = prt::kMaskingNames.parse(f.masking);
  // A flag the chosen material never reads is a mistake worth reporting.
  auto unused = [&](const char* flag, bool used) {
    if (f.command && f.command->count(flag) && !used) {
      throw UsageError(std::string(flag) + " does not apply to --material " + f.material);
    }
  };
  unused("--exponent", m.kind == prt::MaterialKind::kPhong);
  unused("--roughness", m.kind == prt::MaterialKind::kCookTorrance);
  unused("--f0", m.kind == prt::MaterialKind::kCookTorrance);
  unused("--masking", m.kind == prt::MaterialKind::kCookTorrance);
  unused("--specular", m.kind != prt::MaterialKind::kLambert);
  if (m.kind == prt::MaterialKind::kLambert) m.specular = 0.f;
  try {
    m.validate();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return m;
}

prt::BakeOptions resolve_bake_flags(const BakeFlags& f) {
  prt::BakeOptions bake = f.bake;
  bake.kind = f.kind == "diffuse" ? prt::TransferKind::kDiffuse : prt::TransferKind::kGlossy;
  bake.material = resolve_material_flags(f.material);
  bake.view_fit = prt::kViewFitNames.parse(f.view_fit);
  if (f.command && f.command->count("--view-fit") && f.kind == "diffuse")
    throw UsageError("--view-fit applies to --kind glossy only");
  try {
    prt::validate(bake);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return bake;
}

}  // namespace prtr_app
