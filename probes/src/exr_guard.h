// probes/src/exr_guard.h: a strict reading of an OpenEXR file's headers, done before
// OpenImageIO hands the file to OpenEXR. OpenEXR trusts the sizes a header states: it
// allocates an attribute's declared size, a line-offset table with one entry per chunk of the
// data window, and compressor buffers of data-window width x bytes per pixel x lines per
// chunk, all while opening the file. A few hundred bytes of header can ask for gigabytes.
// Every such size is checked here against what the file can hold.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace probes::detail {

// Any one buffer decoded from a file may be at most this many times the file's size (zlib,
// behind OpenEXR's ZIP and PXR24, peaks near 1032:1) ...
constexpr double kMaxExpansion = 4096;
// ... or this many bytes, whatever the file's size: small maps compress very well.
constexpr double kAlwaysAllowedBytes = 64.0 * 1024 * 1024;

// Empty when the file is not an OpenEXR file (OpenImageIO reports that) or when every header
// is consistent with the file's size; otherwise what is wrong and what to do.
std::string check_exr_header(const std::filesystem::path& path, std::uintmax_t file_size);

}  // namespace probes::detail
