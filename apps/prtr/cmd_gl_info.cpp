// prtr gl-info: what the offscreen OpenGL context offers (the register budget's default),
// and with --gl egl the EGL devices there are to choose from (--gl-device).
#include "commands.h"
#include "gl_flags.h"

#include "render/gl_context.h"

#include <cstdio>
#include <memory>

namespace prtr_app {

Runner add_gl_info_command(CLI::App& app) {
  auto flags = std::make_shared<GlFlags>();
  CLI::App* cmd = app.add_subcommand(
      "gl-info", "Create the offscreen OpenGL 4.5 context and print its limits (and EGL devices)");
  add_gl_flags(cmd, *flags);
  return [flags] {
    const render::GlSelection selection = gl_selection(*flags);
    if (selection.backend == render::GlBackend::kEgl) {
      for (const render::EglDevice& d : render::list_egl_devices()) {
        std::printf("egl device  %d: %s%s%s%s\n", d.index,
                    d.software ? "software (Mesa llvmpipe)" : "hardware",
                    d.vendor.empty() ? "" : (", " + d.vendor).c_str(),
                    d.drm_file.empty() ? "" : ", ", d.drm_file.c_str());
        std::printf("            %s\n", d.extensions.c_str());
      }
    }
    render::GlContext context(selection);
    const render::GlInfo info = context.info();
    std::printf("backend     %s\n", context.description().c_str());
    std::printf("version     %s (%s profile)\n", info.version.c_str(),
                info.core_profile ? "core" : "compatibility");
    std::printf("renderer    %s\n", info.renderer.c_str());
    std::printf("glsl        %s\n", info.glsl_version.c_str());
    std::printf("registers   %d vec4 vertex uniforms\n", info.max_vertex_uniform_vectors);
    std::printf("budget      %d vec4 (default register budget per pass)\n",
                info.default_register_budget());
    std::printf("ubo         %d bytes max uniform block\n", info.max_uniform_block_size);
    std::printf("ssbo        %lld bytes max storage block\n", info.max_ssbo_size);
  };
}

}  // namespace prtr_app
