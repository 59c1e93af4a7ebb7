// overdraw/plot.h: the overdraw benchmark's two plots, drawn by prtr itself
// (render/false_colour.h's Picture, text through OpenImageIO) and written atomically as PNG:
//  - the Pareto plot: per cluster count K one panel of Average SE against average overdraw,
//    one marker per measured row (colour = method), the rows no other row beats on both
//    axes joined by a line, and the thesis's published best overdraw at that K as a dashed
//    vertical line;
//  - the timing plot: GL ms, FPS and process CPU ms against average overdraw for every row,
//    the median as a marker, the interquartile range as a whisker and the least-squares line
//    (OverdrawReport::gl_fit, fps_fit, process_cpu_fit) with its R^2.
// The geometry is public so that a test can find a marker from the data alone.
#pragma once

#include "overdraw/report.h"

#include "render/false_colour.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace overdraw {

// Every panel is kPanelWidth x kPanelHeight pixels, panels fill rows of kPanelColumns from
// the top left below a kTitleHeight title strip. Inside a panel the plotting area is inset by
// the margins; data maps linearly onto it, x to the right, y upwards, the range of each axis
// being padded_range of the values it shows.
inline constexpr int kPanelWidth = 560, kPanelHeight = 420, kPanelColumns = 2;
inline constexpr int kTitleHeight = 34;
inline constexpr int kMarginLeft = 84, kMarginRight = 16, kMarginTop = 30, kMarginBottom = 56;
inline constexpr int kMarkerHalf = 4;  // markers are (2 kMarkerHalf + 1)^2 filled squares

// [lo - 8 % of the span, hi + 8 %]; a zero span becomes 10 % of |lo| (or 1 at 0) each side.
struct Range {
  double lo = 0, hi = 1;
};
Range padded_range(double lo, double hi);

struct PanelAxes {
  int left = 0, top = 0, width = 0, height = 0;  // the plotting area in pixels
  Range x, y;
  // Pixel centre of a data point: left + (x - x.lo) / (x.hi - x.lo) (width - 1), rounded;
  // y likewise from the bottom row of the area upwards.
  int px(double v) const;
  int py(double v) const;
};
// The plotting area of panel `index` (0-based, row-major).
PanelAxes panel_axes(int index, Range x, Range y);

// The method colours, in the order methods first appear in the rows.
render::Colour8 method_colour(int method_index);

// The thesis's best average overdraw per K at 3 clusters per pass (bunny, Cook-Torrance,
// tables 5.14-5.17): the dashed line in the Pareto panels of the thesis budget.
const std::map<int, double>& thesis_best_overdraw();

// Rows of `budget` only; `thesis` adds the dashed lines (empty: none). Throws
// std::invalid_argument when no row has that budget.
render::Picture pareto_plot(const OverdrawReport& report, const std::string& budget,
                            const std::map<int, double>& thesis);
// Three panels (GL ms, FPS, process CPU ms) over every row of the report.
render::Picture timing_plot(const OverdrawReport& report);

}  // namespace overdraw
