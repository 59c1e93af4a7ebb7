// apps/prtr/gl_flags.h: --gl osmesa|egl and --gl-device N, on every command that renders.
// Their defaults come from PRTR_GL and PRTR_GL_DEVICE, so a whole session (or a test run) can
// switch backend without repeating the flags; a flag given beats the environment.
#pragma once

#include "render/gl_context.h"

#include <CLI/CLI.hpp>

#include <string>

namespace prtr_app {

struct GlFlags {
  std::string backend = "osmesa";
  int device = -1;  // -1: the first hardware EGL device, else Mesa's
};

void add_gl_flags(CLI::App* cmd, GlFlags& flags);

// --accumulation auto|rgba32f|rgba16f: the colour target's format (render::Accumulation).
void add_accumulation_flag(CLI::App* cmd, std::string& name);

// --constants auto|cpu|gpu: where the per-frame constants are computed (render::Constants).
void add_constants_flag(CLI::App* cmd, std::string& name);

// The backend and device the flags name. An EGL device index beyond those EGL lists is a
// UsageError (exit 2) naming the count; EGL that cannot be loaded at all fails as GlError.
render::GlSelection gl_selection(const GlFlags& flags);

}  // namespace prtr_app
