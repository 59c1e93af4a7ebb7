// prtr compare IMAGE REFERENCE: the error of a rendering against a reference image (prtr
// path-trace), over the pixels the mesh covers in both (render/image_difference.h).
#include "commands.h"
#include "common/json.h"
#include "common/output_path.h"
#include "flag_checks.h"

#include "render/image.h"
#include "render/image_difference.h"

#include <cstdio>
#include <string>

namespace prtr_app {
// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_compare {

struct Options {
  std::string image, reference, second_reference;
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
  cmd->add_option("--second-reference", o.second_reference,
                  "The reference traced again with another --seed: takes the references' own "
                  "noise out of the error (reference noise, error against the exact image)");
  cmd->add_flag("--json", o.json, "Print the figures as one JSON line");
}

void run(const Options& o, CLI::App*) {
  const render::Image image = render::read_image(o.image);
  const bool second = !o.second_reference.empty();
  // The same file twice has no difference to measure noise by, and would say there is none.
  if (second && common::same_file(o.second_reference, o.reference))
    throw UsageError("--second-reference " + o.second_reference +
                     " is the reference itself: give the same scene traced with another --seed");
  const render::Image reference = render::read_image(o.reference);
  const render::Image second_reference =
      second ? render::read_image(o.second_reference) : render::Image{};
  render::ImageDifference d;
  try {
    d = render::image_difference(image, reference, float(o.coverage), o.erode,
                                 second ? &second_reference : nullptr);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(o.image + " against " + o.reference +
                             (second ? " and " + o.second_reference : std::string()) + ": " +
                             e.what());
  }
  if (o.json) {
    common::Json j{{"pixels", d.pixels},
                   {"rmse", d.rmse},
                   {"relative_rmse", d.relative_rmse},
                   {"mean_abs", d.mean_abs},
                   {"max_abs", d.max_abs}};
    if (second) {
      j["reference_noise"] = d.reference_noise;
      j["corrected_relative_rmse"] = d.corrected_relative_rmse;
    }
    std::printf("%s\n", common::dump_json(j).c_str());
    return;
  }
  std::printf("pixels         %llu covered in both\n", static_cast<unsigned long long>(d.pixels));
  std::printf("relative RMSE  %.4f (%.2f %%)\n", d.relative_rmse, 100.0 * d.relative_rmse);
  std::printf("RMSE           %.6g\nmean |error|   %.6g\nmax |error|    %.6g\n", d.rmse, d.mean_abs,
              d.max_abs);
  if (second) {
    std::printf("reference noise %.4f (%.2f %%) of one reference, from the two's difference\n",
                d.reference_noise, 100.0 * d.reference_noise);
    std::printf("exact image    %.4f (%.2f %%) relative RMSE with that noise taken out\n",
                d.corrected_relative_rmse, 100.0 * d.corrected_relative_rmse);
  }
}

}  // namespace cmd_compare

Runner add_compare_command(CLI::App& app) {
  return add_command(app, "compare",
                     "Error of a rendering against a reference image over the covered pixels",
                     cmd_compare::add_flags, cmd_compare::run);
}

}  // namespace prtr_app
