#include "viewer/request.h"

#include "cpca/supercluster_strategy.h"
#include "render/pass_capacity.h"
#include "render/shading.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <set>

namespace viewer {
namespace {

// A request value quoted in a reason: bounded and printable, so a reason stays one short line.
std::string quoted(const std::string& value) {
  std::string out;
  for (char c : value.substr(0, 40)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (value.size() > 40) out += "...";
  return "'" + out + "'";
}

[[noreturn]] void reject(const std::string& name, const std::string& value,
                         const std::string& why) {
  throw RequestError(name + "=" + quoted(value) + ": " + why);
}

// The whole text must be the number: from_chars rejects leading spaces and '+', and trailing
// characters are refused here.
double parse_double(const std::string& name, const std::string& text, double lo, double hi) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty())
    reject(name, text, "not a number");
  if (!std::isfinite(value)) reject(name, text, "not a finite number");
  if (value < lo || value > hi) {
    char range[64];
    std::snprintf(range, sizeof range, "out of range [%g, %g]", lo, hi);
    reject(name, text, range);
  }
  return value;
}

long long parse_integer(const std::string& name, const std::string& text, long long lo,
                        long long hi) {
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty())
    reject(name, text, "not an integer");
  if (value < lo || value > hi)
    reject(name, text, "out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return value;
}

bool valid_client(const std::string& id) {
  if (id.empty() || id.size() > 32) return false;
  for (char c : id)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

using Setter = std::function<void(ViewState&, const std::string&, const ViewLimits&)>;

// clusters= or pcs=: 1 to `max`, or 0 for the launch's; refused where the viewer offers no
// other compression.
int compression_size(const char* name, const std::string& v, int max) {
  if (max <= 0 && v != "0") reject(name, v, "this viewer offers only its launch compression");
  return int(parse_integer(name, v, 0, max));
}

void set_client(ViewState& s, const std::string& v, const ViewLimits&) {
  if (!valid_client(v)) reject("client", v, "use 1-32 of A-Z a-z 0-9 _ -");
  s.client = v;
}

void set_mode(ViewState& s, const std::string& v, const ViewLimits& l) {
  try {
    s.mode = render::kModeNames.parse(v);
  } catch (const std::invalid_argument&) {
    reject("mode", v, "unknown render mode");
  }
  if (s.mode == render::Mode::kUncompressed && !l.uncompressed)
    reject("mode", v, "the transfer set is not loaded");
}

void set_strategy(ViewState& s, const std::string& v, const ViewLimits&) {
  try {
    cpca::find_supercluster_strategy(v);
  } catch (const std::invalid_argument&) {
    reject("strategy", v, "use " + cpca::supercluster_strategy_names());
  }
  s.strategy = v;
}

void set_overlay(ViewState& s, const std::string& v, const ViewLimits& l) {
  try {
    s.overlay = kOverlayNames.parse(v);
  } catch (const std::invalid_argument&) {
    reject("overlay", v, "use " + kOverlayNames.list());
  }
  if (s.overlay == Overlay::kDifference && !l.uncompressed)
    reject("overlay", v, "the uncompressed transfer is not at hand");
}

// One entry per parameter: its name and how it lands in the state. Angles accept any finite
// value a page could accumulate by dragging, but not the magnitudes where degrees lose their
// fraction; the camera does not go over the pole (its up vector would flip).
const std::vector<std::pair<std::string, Setter>>& setters() {
  using S = ViewState;
  using V = const std::string&;
  using L = const ViewLimits&;
  static const std::vector<std::pair<std::string, Setter>> table = {
      {"client", set_client},
      {"seq", [](S& s, V v, L) { s.seq = std::uint64_t(parse_integer("seq", v, 0, INT64_MAX)); }},
      {"w", [](S& s, V v, L l) { s.width = int(parse_integer("w", v, 16, l.max_side)); }},
      {"h", [](S& s, V v, L l) { s.height = int(parse_integer("h", v, 16, l.max_side)); }},
      {"env_yaw", [](S& s, V v, L) { s.env_yaw = parse_double("env_yaw", v, -1e6, 1e6); }},
      {"env_pitch", [](S& s, V v, L) { s.env_pitch = parse_double("env_pitch", v, -1e6, 1e6); }},
      {"cam_yaw", [](S& s, V v, L) { s.cam_yaw = parse_double("cam_yaw", v, -1e6, 1e6); }},
      {"cam_pitch", [](S& s, V v, L) { s.cam_pitch = parse_double("cam_pitch", v, -89, 89); }},
      {"zoom", [](S& s, V v, L) { s.zoom = parse_double("zoom", v, 0.1, 20); }},
      {"mode", set_mode},
      {"strategy", set_strategy},
      {"budget",
       [](S& s, V v, L l) {
         s.register_budget = int(parse_integer("budget", v, 0, l.max_register_budget));
       }},
      // After "clusters" (the table is read in key order): a pass holds at most all clusters.
      {"cpp",
       [](S& s, V v, L l) {
         s.clusters_per_pass =
             int(parse_integer("cpp", v, 0, s.clusters > 0 ? s.clusters : l.cluster_count));
       }},
      {"clusters",
       [](S& s, V v, L l) { s.clusters = compression_size("clusters", v, l.max_clusters); }},
      {"pcs", [](S& s, V v, L l) { s.pcs = compression_size("pcs", v, l.max_components); }},
      {"order", [](S& s, V v, L l) { s.order = compression_size("order", v, l.max_order); }},
      {"probe",
       [](S& s, V v, L l) { s.probe = int(parse_integer("probe", v, 0, l.probe_count - 1)); }},
      {"exposure", [](S& s, V v, L) { s.exposure = parse_double("exposure", v, -20, 20); }},
      {"overlay", set_overlay},
      {"aa", [](S& s, V v, L) { s.samples = int(parse_integer("aa", v, 1, 4)); }},
  };
  return table;
}

}  // namespace

namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percent_decode(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '+') {
      out += ' ';
    } else if (text[i] != '%') {
      out += text[i];
    } else {
      const int hi = i + 2 < text.size() ? hex_digit(text[i + 1]) : -1;
      const int lo = hi >= 0 ? hex_digit(text[i + 2]) : -1;
      if (lo < 0) throw RequestError("bad %-escape in " + quoted(text));
      out += char(hi * 16 + lo);
      i += 2;
    }
  }
  return out;
}

}  // namespace

QueryParams parse_query(const std::string& raw) {
  QueryParams params;
  if (raw.empty()) return params;
  if (raw.find(';') != std::string::npos)
    throw RequestError("';' is not a parameter separator; use '&'");
  std::size_t begin = 0;
  while (begin <= raw.size()) {
    const std::size_t end = std::min(raw.find('&', begin), raw.size());
    const std::string pair = raw.substr(begin, end - begin);
    if (pair.empty()) throw RequestError("empty parameter (a stray '&')");
    const std::size_t eq = pair.find('=');
    if (eq == std::string::npos)
      throw RequestError("parameter " + quoted(percent_decode(pair)) + " has no value");
    const std::string key = percent_decode(pair.substr(0, eq));
    if (pair.find('=', eq + 1) != std::string::npos)
      throw RequestError("parameter " + quoted(key) + ": '=' in its value");
    if (params.count(key)) throw RequestError("parameter " + quoted(key) + " repeated");
    params.emplace(key, percent_decode(pair.substr(eq + 1)));
    begin = end + 1;
  }
  return params;
}

std::vector<std::string> view_parameter_names() {
  std::vector<std::string> names;
  for (const auto& [name, setter] : setters()) names.push_back(name);
  return names;
}

namespace {

// The budget and clusters per pass, in the page's words: render::check_pass_capacity
// decides (the renderer's own refusal names command-line flags), this says which values
// would fit.
void check_passes(const ViewState& state, const ViewLimits& limits) {
  const bool other = (state.pcs > 0 || state.order > 0) && limits.launch_order > 0;
  const int cost = other ? render::constant_layout(
                               state.order > 0 ? state.order : limits.launch_order, limits.glossy,
                               state.pcs > 0 ? state.pcs : limits.launch_components)
                               .registers_per_cluster()
                         : limits.registers_per_cluster;
  const render::PassCapacity c =
      render::check_pass_capacity(std::max(1, cost), state.register_budget,
                                  limits.max_register_budget, state.clusters_per_pass);
  const std::string context = std::to_string(limits.max_register_budget);
  switch (c.problem) {
    case render::CapacityProblem::kNone:
      return;
    case render::CapacityProblem::kBudgetAboveContext:  // the parser's range already refuses it
    case render::CapacityProblem::kBudgetBelowCluster:
      throw RequestError("budget=" + std::to_string(state.register_budget) +
                         ": below one cluster's " + std::to_string(c.registers_per_cluster) +
                         " registers; use 0 (the context's " + context + ") or " +
                         std::to_string(c.registers_per_cluster) + " to " + context);
    case render::CapacityProblem::kTooManyPerPass:
      throw RequestError("cpp=" + std::to_string(state.clusters_per_pass) + ": " +
                         std::to_string(c.clusters_per_pass) + " clusters fit the budget of " +
                         std::to_string(c.register_budget) +
                         " registers; use 0 (all that fit) or 1 to " +
                         std::to_string(c.clusters_per_pass));
  }
}

}  // namespace

ViewState parse_view_request(const QueryParams& params, const ViewLimits& limits,
                             const ViewState& defaults) {
  ViewState state = defaults;
  std::set<std::string> seen;
  for (const auto& [name, value] : params) {
    const auto& table = setters();
    // A named reference: clang 14 in C++17 (the fuzz build) cannot capture a structured
    // binding.
    const std::string& key = name;
    const auto it = std::find_if(table.begin(), table.end(),
                                 [&key](const auto& entry) { return entry.first == key; });
    if (it == table.end()) throw RequestError("unknown parameter " + quoted(name));
    if (!seen.insert(name).second) throw RequestError("parameter " + quoted(name) + " repeated");
    it->second(state, value, limits);
  }
  if (std::int64_t(state.width) * state.height > limits.max_pixels)
    throw RequestError("w x h = " + std::to_string(state.width) + " x " +
                       std::to_string(state.height) + ": more than " +
                       std::to_string(limits.max_pixels) + " pixels");
  const long long samples =
      std::int64_t(state.width) * state.height * state.samples * state.samples;
  if (samples > limits.max_pixels)
    throw RequestError("aa=" + std::to_string(state.samples) + ": " + std::to_string(state.width) +
                       " x " + std::to_string(state.height) + " pixels at " +
                       std::to_string(state.samples * state.samples) +
                       " samples each are more than " + std::to_string(limits.max_pixels) +
                       "; use aa=1 at this size");
  check_passes(state, limits);
  return state;
}

}  // namespace viewer
