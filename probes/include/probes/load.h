// probes/load.h: reading HDR environment maps with OpenImageIO (EXR, HDR, and anything else
// it reads). Integer formats (PNG, JPEG, ...) are decoded to linear values on load from the
// colour space OpenImageIO reports: sRGB, or a stated gamma; sRGB when none is named.
//
// Layouts:
//  - lat-long: width == 2 * height (see probes/probe.h for the direction mapping);
//  - angular (Debevec "light probe"): square; the disc centre looks toward -Z, the rim is
//    +Z, image right is +X and image up is +Y. A direction at angle a from -Z lands at
//    radius a / pi of the half-width along its (x, y) direction. Resampled (bilinear) to a
//    lat-long map of 2N x N for an N x N angular map.
//
// Bad texels: NaN or Inf refuses the file (the map is corrupt and no fix is safe); negative
// values, which some HDR tools leave after filtering, are clamped to 0 and counted.
#pragma once

#include "probes/probe.h"

#include <cstddef>
#include <filesystem>
#include <string>

namespace probes {

enum class Layout { kAuto, kLatLong, kAngular };

struct LoadOptions {
  Layout layout = Layout::kAuto;  // kAuto: 2:1 is lat-long, 1:1 is angular, else an error
};

struct LoadReport {
  std::string path;
  std::string format;  // OpenImageIO's format name, e.g. "openexr"
  int file_width = 0;
  int file_height = 0;
  int file_channels = 0;
  Layout layout = Layout::kAuto;  // the layout actually used
  std::size_t negative_texels_clamped = 0;
};

// Throws ProbeError naming the path for: a missing or unreadable file, fewer than three
// channels (one-channel maps are taken as grey), a wrong aspect ratio, NaN/Inf texels.
Probe load_probe(const std::filesystem::path& path, const LoadOptions& options = {},
                 LoadReport* report = nullptr);

const char* layout_name(Layout layout);

}  // namespace probes
