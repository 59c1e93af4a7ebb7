// apps/prtr/bake_flags.h: the bake flags (--kind, --order, --samples, --bounces, --seed,
// --material and its parameters, --masking, --view-fit, --ray-offset), shared by every command that
// bakes: prtr bake, and prtr relight / overdraw through the cache.
#pragma once

#include "prt/bake.h"

#include <CLI/CLI.hpp>

#include <string>

namespace prtr_app {

// The material flags (--material, --albedo, --specular, --exponent, --roughness, --f0,
// --masking): part of the bake flags, and alone for the commands that shade without an SH
// bake (prtr slf, prtr path-trace).
struct MaterialFlags {
  std::string material = "phong", albedo = "0.5", masking = "smith";
  prt::Material values;
  CLI::App* command = nullptr;
};
void add_material_flags(CLI::App* command, MaterialFlags& flags);
// The material, validated; UsageError naming the flag otherwise (also for a parameter the
// chosen material never reads).
prt::Material resolve_material_flags(const MaterialFlags& flags);

struct BakeFlags {
  std::string kind = "glossy", view_fit = "least-squares";
  MaterialFlags material;  // --material and its parameters, resolved into bake.material
  prt::BakeOptions bake;
  CLI::App* command = nullptr;  // to tell which flags were given
};

// `with_slf`: --kind also takes slf (prtr relight: a surface light field instead of PRT),
// which resolve_bake_flags does not resolve; the command reads the flags it shares itself.
void add_bake_flags(CLI::App* command, BakeFlags& flags, bool with_slf = false);

// The options the flags describe, validated; UsageError naming the flag otherwise (also for
// a material parameter the chosen material never reads).
prt::BakeOptions resolve_bake_flags(const BakeFlags& flags);

}  // namespace prtr_app
