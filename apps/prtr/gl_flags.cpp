#include "gl_flags.h"

#include "commands.h"
#include "flag_checks.h"
#include "render/renderer.h"

namespace prtr_app {

void add_gl_flags(CLI::App* cmd, GlFlags& flags) {
  cmd->add_option("--gl", flags.backend,
                  "OpenGL backend: osmesa (Mesa's llvmpipe on the CPU, runs anywhere) or egl "
                  "(an EGL device: a GPU where there is one)")
      ->envname("PRTR_GL")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            if (render::parse_gl_backend(text)) return {};
            return "'" + text + "' is not a GL backend (--gl or PRTR_GL): use osmesa or egl";
          },
          "osmesa|egl"))
      ->capture_default_str();
  cmd->add_option("--gl-device", flags.device,
                  "EGL device index for --gl egl (prtr gl-info lists them; default: the first "
                  "GPU, else Mesa's software device)")
      ->envname("PRTR_GL_DEVICE")
      ->check(integer_in(0, 1 << 20));
}

void add_accumulation_flag(CLI::App* cmd, std::string& name) {
  add_checked_option(
      cmd, "--accumulation", name,
      "Format the passes add into: rgba32f, rgba16f (six times the blending rate on a GPU, 11 "
      "significant bits), or auto (rgba16f on a GPU, rgba32f on Mesa's software rasterisers)",
      CLI::IsMember(render::kAccumulationNames.names()));
}

void add_constants_flag(CLI::App* cmd, std::string& name) {
  add_checked_option(cmd, "--constants", name,
                     "Where each frame's lighting constants are computed: cpu, gpu (one compute "
                     "dispatch over the clusters' rows in video memory), or auto (gpu on a "
                     "hardware GPU, cpu on Mesa's software rasterisers)",
                     CLI::IsMember(render::kConstantsNames.names()));
}

render::GlSelection gl_selection(const GlFlags& flags) {
  render::GlSelection s;
  const auto backend = render::parse_gl_backend(flags.backend);
  if (!backend) throw UsageError("--gl " + flags.backend + ": use osmesa or egl");
  s.backend = *backend;
  s.device = flags.device;
  if (s.backend == render::GlBackend::kEgl && s.device >= 0) {
    const std::size_t count = render::list_egl_devices().size();
    if (std::size_t(s.device) >= count)
      throw UsageError("--gl-device " + std::to_string(s.device) + ": EGL lists " +
                       std::to_string(count) + " device" + (count == 1 ? "" : "s") +
                       " (prtr gl-info --gl egl lists them)");
  }
  return s;
}

}  // namespace prtr_app
