// viewer/src/difference.h (private): the difference view, a compressed frame against the
// uncompressed one, as PRTDemo showed it.
//
// Per pixel covered by the mesh in either frame, the relative luminance difference
// |L(test) - L(reference)| / max(L(reference), floor), where the floor (1 % of the reference's
// mean luminance over the mesh) keeps dark pixels from dominating; shown in false colour from
// 0 (dark blue) to `full_scale` and beyond (red), with a scale bar in the top-left corner.
// Background pixels stay transparent (the frame shows through).
#pragma once

#include "render/false_colour.h"
#include "render/image.h"

namespace viewer::detail {

struct DifferenceStats {
  double rms = 0;  // relative, over the mesh's pixels
  double max = 0;
};

// Throws std::invalid_argument when the two images differ in size.
render::Picture difference_picture(const render::Image& test, const render::Image& reference,
                                   double full_scale, const render::Colour8& transparent,
                                   DifferenceStats* stats = nullptr);

// The false-colour ramp: 0 -> dark blue, 0.25 cyan, 0.5 green, 0.75 yellow, 1 and above red.
render::Colour8 difference_colour(double t);

}  // namespace viewer::detail
