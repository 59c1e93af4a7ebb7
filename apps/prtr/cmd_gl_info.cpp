// prtr gl-info: what the offscreen OpenGL context offers (the register budget's default).
#include "commands.h"

#include "render/gl_context.h"

#include <cstdio>

namespace prtr_app {

Runner add_gl_info_command(CLI::App& app) {
  app.add_subcommand("gl-info", "Create the offscreen OpenGL 4.5 context and print its limits");
  return [] {
    render::GlContext context;
    const render::GlInfo info = context.info();
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
