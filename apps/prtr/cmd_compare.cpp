// prtr compare IMAGE REFERENCE: the error of a rendering against a reference image (prtr
// path-trace), over the pixels the mesh covers in both (render/image_difference.h).
#include "commands.h"
#include "common/json.h"
#include "flag_checks.h"

#include "render/image.h"
#include "render/image_difference.h"

#include <cstdio>
#include <string>

namespace prtr_app {
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_compare {

struct Options {
  std::string image, reference;
  double coverage = 0.999;
  int erode = 0;
  bool json = false;
};

void add_flags(CLI::App* cmd, Options& o) {
  cmd->add_option("IMAGE", o.image, "Rendered image (EXR, alpha = coverage)")->required();
  cmd->add_option("REFERENCE", o.reference, "Reference image of the same size")->required();
  add_checked_option(cmd, "--coverage", o.coverage,
                     "Compare pixels whose alpha is at least this in both (0: every pixel)",
                     number_in(0.0, 1.0));
  add_checked_option(cmd, "--erode", o.erode,
                     "Compare only pixels at least this many pixels inside the covered region "
                     "of both (0: every covered pixel; silhouettes left out)",
                     integer_in(0, 1024));
  cmd->add_flag("--json", o.json, "Print the figures as one JSON line");
}

void run(const Options& o, CLI::App*) {
  const render::Image image = render::read_image(o.image);
  const render::Image reference = render::read_image(o.reference);
  render::ImageDifference d;
  try {
    d = render::image_difference(image, reference, float(o.coverage), o.erode);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(o.image + " against " + o.reference + ": " + e.what());
  }
  if (o.json) {
    std::printf("%s\n", common::dump_json(common::Json{{"pixels", d.pixels},
                                                       {"rmse", d.rmse},
                                                       {"relative_rmse", d.relative_rmse},
                                                       {"mean_abs", d.mean_abs},
                                                       {"max_abs", d.max_abs}})
                            .c_str());
    return;
  }
  std::printf("pixels         %llu covered in both\n", static_cast<unsigned long long>(d.pixels));
  std::printf("relative RMSE  %.4f (%.2f %%)\n", d.relative_rmse, 100.0 * d.relative_rmse);
  std::printf("RMSE           %.6g\nmean |error|   %.6g\nmax |error|    %.6g\n", d.rmse, d.mean_abs,
              d.max_abs);
}

}  // namespace cmd_compare

Runner add_compare_command(CLI::App& app) {
  return add_command(app, "compare",
                     "Error of a rendering against a reference image over the covered pixels",
                     cmd_compare::add_flags, cmd_compare::run);
}

}  // namespace prtr_app
