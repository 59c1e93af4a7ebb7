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
//  - cube maps (probes/cube_map.h): a 4:3 horizontal or 3:4 vertical cross, or six face
//    files -- a folder holding px, nx, py, ny, pz, nz (any image format, e.g. px.exr), or a
//    path with "{face}" standing for those names (sky_{face}.hdr). The renderer samples
//    lat-long maps, so a cube of face size N is resampled (bilinear) to a 4N x 2N lat-long
//    map on load; the cube itself rides along (Probe::source_cube, and the report) for an
//    exact SH projection.
//
// Bad texels: NaN or Inf refuses the file (the map is corrupt and no fix is safe); negative
// values, which some HDR tools leave after filtering, are clamped to 0 and counted.
#pragma once

#include "probes/cube_map.h"
#include "probes/probe.h"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

namespace probes {

enum class Layout { kAuto, kLatLong, kAngular, kCross, kFaces };

struct LoadOptions {
  // kAuto: a folder or a name with {face} is a six-face set; an image of 2:1 is lat-long, 1:1
  // angular, 4:3 a horizontal and 3:4 a vertical cross; anything else is an error.
  Layout layout = Layout::kAuto;
};

struct LoadReport {
  std::string path;
  std::string format;  // OpenImageIO's format name, e.g. "openexr"
  int file_width = 0;
  int file_height = 0;
  int file_channels = 0;
  Layout layout = Layout::kAuto;  // the layout actually used
  std::size_t negative_texels_clamped = 0;
  // Cube maps (cross or faces): the cube as read, for an exact per-texel projection, and for a
  // cross which kind it was. The returned Probe is its lat-long resampling.
  std::shared_ptr<const CubeMap> cube;
  CrossKind cross = CrossKind::kHorizontal;
};

// Throws ProbeError naming the path for: a missing or unreadable file, fewer than three
// channels (one-channel maps are taken as grey), a wrong aspect ratio, NaN/Inf texels, a face
// set with a face missing or of another size.
Probe load_probe(const std::filesystem::path& path, const LoadOptions& options = {},
                 LoadReport* report = nullptr);

const char* layout_name(Layout layout);

}  // namespace probes
