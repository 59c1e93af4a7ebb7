// viewer/request.h: the view state a browser asks `prtr view` to render, and the strict
// parser that turns a request's query parameters into it. Every request carries the whole
// state (the server keeps no view state per client, so tabs cannot disturb each other);
// anything unknown, repeated, malformed, non-finite or out of range is rejected with a
// one-line reason (HTTP 400). No parameter is ever used as a path: the probe is an index into
// the list the server scanned at start-up.
#pragma once

#include "common/enum_names.h"

#include "render/renderer.h"

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace viewer {

enum class Overlay { kNone, kOverdraw, kClusters, kDifference };
inline constexpr auto kOverlayNames =
    common::enum_table<Overlay>("overlay", {{Overlay::kNone, "none"},
                                            {Overlay::kOverdraw, "overdraw"},
                                            {Overlay::kClusters, "clusters"},
                                            {Overlay::kDifference, "difference"}});

struct ViewState {
  std::string client = "default";  // [A-Za-z0-9_-]{1,32}: coalescing key
  std::uint64_t seq = 0;           // the client's request counter: a larger one is newer
  int width = 960, height = 710;
  double env_yaw = 0, env_pitch = 0;  // degrees: environment rotation (lighting + background)
  double cam_yaw = 0, cam_pitch = 0;  // degrees: camera orbit about the mesh's centre
  double zoom = 1;                    // > 1 moves the camera closer
  render::Mode mode = render::Mode::kDecoupled;
  std::string strategy = "greedy-refine";
  int register_budget = 0;    // vec4 per pass; 0: the context's
  int clusters_per_pass = 0;  // 0: as many as the budget holds
  int probe = 0;              // index into ViewLimits::probe_count
  double exposure = 0;        // stops
  Overlay overlay = Overlay::kNone;
  int samples = 1;  // anti-aliasing: samples x samples per pixel, box-filtered (1: off)
  // The compression to show (viewer/compressions.h); 0: the launch's clusters, PCs or SH order.
  int clusters = 0, pcs = 0, order = 0;
};

// What the server accepts; the parser checks against it.
struct ViewLimits {
  int probe_count = 1;
  int cluster_count = 1;
  bool uncompressed = false;  // the transfer set is at hand
  int max_side = 4096;
  long long max_pixels = 4096LL * 2048;
  int max_register_budget = 1 << 20;  // what the GL context offers
  int registers_per_cluster = 1;      // one cluster's constants; a budget below fits none
  // Other compressions the page may ask for (0: none): clusters up to max_clusters, PCs up to
  // max_components, SH orders up to max_order (another order bakes first). A cluster of the
  // asked-for PCs and order (the launch's where not asked; launch_order 0: not priced) takes
  // the registers render::constant_layout gives it.
  int max_clusters = 0, max_components = 0, max_order = 0;
  int launch_order = 0, launch_components = 0;
  bool glossy = true;
};

class RequestError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

using QueryParams = std::multimap<std::string, std::string>;

// The parameters of a raw query string (after '?', still percent-encoded), strictly:
// '&'-separated key=value pairs, each key once. A ';' separator, an empty pair, a key without
// '=', a second '=' in a pair (trailing garbage), a repeated key or a bad %-escape is a
// RequestError with a one-line reason. '+' is a space, as browsers encode it.
QueryParams parse_query(const std::string& raw);

// The state `params` describe (unnamed fields keep `defaults`); throws RequestError.
ViewState parse_view_request(const QueryParams& params, const ViewLimits& limits,
                             const ViewState& defaults = {});

// The names parse_view_request accepts, for the page and the tests.
std::vector<std::string> view_parameter_names();

}  // namespace viewer
