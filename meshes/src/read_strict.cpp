#include "read_strict.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>

namespace meshes::detail {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_space(s[i])) ++i;
    const std::size_t begin = i;
    while (i < s.size() && !is_space(s[i])) ++i;
    if (i > begin) out.push_back(s.substr(begin, i - begin));
  }
  return out;
}

// Whole-token parses: trailing characters make the token invalid.
template <class T>
std::optional<T> parse_int(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  T v{};
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::optional<double> parse_real(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  // Out-of-range values are kept as the infinity they overflow to; the loader reports
  // non-finite coordinates with the vertex index.
  if (ec == std::errc::result_out_of_range && end == s.data() + s.size()) {
    return s.front() == '-' ? -std::numeric_limits<double>::infinity()
                            : std::numeric_limits<double>::infinity();
  }
  if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return v;
}

std::string quote(std::string_view token) {
  constexpr std::size_t kShown = 24;
  std::string out = "'";
  for (char c : token.substr(0, kShown)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    }
  }
  if (token.size() > kShown) out += "...";
  return out + "'";
}

// Splits text into lines without copying; the last line may lack its newline.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (at_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', at_);
    const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(at_, stop - at_);
    at_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++number_;
    return true;
  }
  std::size_t number() const { return number_; }  // 1-based number of the last line
  std::size_t remaining() const { return text_.size() - at_; }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
  std::size_t number_ = 0;
};

constexpr std::uint64_t kMaxIndexable = std::numeric_limits<std::uint32_t>::max();

}  // namespace

// --- OFF ------------------------------------------------------------------------------------

namespace {

// Records of an OFF file: lines with content, comments ('#' to the end of the line) removed.
class OffRecords {
 public:
  explicit OffRecords(std::string_view bytes) : lines_(bytes) {}
  bool next(std::vector<std::string_view>& tokens) {
    std::string_view line;
    while (lines_.next(line)) {
      const std::size_t hash = line.find('#');
      tokens = split(hash == std::string_view::npos ? line : line.substr(0, hash));
      if (!tokens.empty()) return true;
    }
    return false;
  }
  std::string at_line() const { return "line " + std::to_string(lines_.number()) + ": "; }
  std::size_t remaining() const { return lines_.remaining(); }

 private:
  Lines lines_;
};

// The header and the counts, checked against the bytes that follow.
std::string read_off_header(OffRecords& records, std::uint64_t& nv, std::uint64_t& nf) {
  std::vector<std::string_view> tokens;
  if (!records.next(tokens)) return "no OFF header (the file holds only blank lines or comments)";
  // [ST][C][N][4][n]OFF: the prefixes add per-vertex values after x y z, which are skipped.
  const std::string_view keyword = tokens.front();
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF") {
    return "the first line is " + quote(keyword) + ", not an OFF header";
  }
  const std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  if (prefix.find_first_not_of("STCN") != std::string_view::npos) {
    return "header " + quote(keyword) +
           ": only 3D OFF is read (4OFF and nOFF are not); convert the file to PLY or 3D OFF";
  }
  tokens.erase(tokens.begin());
  if (!tokens.empty() && tokens.front() == "BINARY") {
    return "binary OFF is not read; convert the file to ASCII OFF or to PLY";
  }
  // The counts may share the header's line.
  if (tokens.empty() && !records.next(tokens)) return "the file ends before the element counts";
  if (tokens.size() < 2) return records.at_line() + "expected 'vertices faces [edges]' counts";
  const auto v = parse_int<std::uint64_t>(tokens[0]);
  const auto f = parse_int<std::uint64_t>(tokens[1]);
  if (!v || !f) {
    return records.at_line() + "the counts " + quote(tokens[0]) + " " + quote(tokens[1]) +
           " are not non-negative integers";
  }
  nv = *v;
  nf = *f;
  // The shortest vertex line is "0 0 0\n" (6 bytes), the shortest face "0\n" (2 bytes): a
  // header claiming more than the rest of the file can hold is damaged, and is refused before
  // anything is sized from it.
  const std::uint64_t left = records.remaining();
  if (nv > kMaxIndexable || nf > kMaxIndexable || nv > left / 6 || nf > (left - 6 * nv) / 2) {
    return "the header claims " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
           " faces, but only " + std::to_string(left) +
           " bytes follow it (at least 6 per vertex and 2 per face are needed); the header is "
           "wrong or the file is truncated";
  }
  return {};
}

std::string read_off_vertices(OffRecords& records, std::uint64_t nv, RawPolygons& out) {
  std::vector<std::string_view> tokens;
  out.positions.reserve(nv);
  for (std::uint64_t v = 0; v < nv; ++v) {
    if (!records.next(tokens)) {
      return "the file ends after " + std::to_string(v) + " of the " + std::to_string(nv) +
             " vertices its header claims; the file is truncated or the header is wrong";
    }
    if (tokens.size() < 3) {
      return records.at_line() + "vertex " + std::to_string(v) + " has no x y z";
    }
    double p[3];
    for (int k = 0; k < 3; ++k) {
      const auto x = parse_real(tokens[std::size_t(k)]);
      if (!x) {
        return records.at_line() + "vertex " + std::to_string(v) + ": " +
               quote(tokens[std::size_t(k)]) + " is not a number";
      }
      p[k] = *x;
    }
    out.positions.emplace_back(float(p[0]), float(p[1]), float(p[2]));
  }
  return {};
}

std::string read_off_faces(OffRecords& records, std::uint64_t nf, RawPolygons& out) {
  std::vector<std::string_view> tokens;
  out.face_offsets.reserve(nf + 1);
  for (std::uint64_t f = 0; f < nf; ++f) {
    if (!records.next(tokens)) {
      return "the file ends after " + std::to_string(f) + " of the " + std::to_string(nf) +
             " faces its header claims; the file is truncated or the header is wrong";
    }
    const std::string where = records.at_line() + "face " + std::to_string(f);
    const auto k = parse_int<std::uint64_t>(tokens[0]);
    if (!k) {
      return where + ": the corner count " + quote(tokens[0]) + " is not a non-negative integer";
    }
    // Anything after the corners (a colour) is allowed and skipped.
    if (*k > tokens.size() - 1) {
      return where + " claims " + std::to_string(*k) + " corners but its line lists " +
             std::to_string(tokens.size() - 1) + " values";
    }
    for (std::size_t c = 1; c <= *k; ++c) {
      const auto index = parse_int<std::int64_t>(tokens[c]);
      if (!index) return where + ": " + quote(tokens[c]) + " is not a vertex index";
      out.corners.push_back(*index);
    }
    out.face_offsets.push_back(out.corners.size());
  }
  return {};
}

}  // namespace

std::string read_off(std::string_view bytes, RawPolygons& out) {
  OffRecords records(bytes);
  std::uint64_t nv = 0, nf = 0;
  if (std::string problem = read_off_header(records, nv, nf); !problem.empty()) return problem;
  if (std::string problem = read_off_vertices(records, nv, out); !problem.empty()) return problem;
  return read_off_faces(records, nf, out);
}

// --- PLY ------------------------------------------------------------------------------------

namespace {

enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<Scalar> scalar_of(std::string_view name) {
  if (name == "char" || name == "int8") return Scalar::kInt8;
  if (name == "uchar" || name == "uint8") return Scalar::kUint8;
  if (name == "short" || name == "int16") return Scalar::kInt16;
  if (name == "ushort" || name == "uint16") return Scalar::kUint16;
  if (name == "int" || name == "int32") return Scalar::kInt32;
  if (name == "uint" || name == "uint32") return Scalar::kUint32;
  if (name == "float" || name == "float32") return Scalar::kFloat32;
  if (name == "double" || name == "float64") return Scalar::kFloat64;
  return std::nullopt;
}

std::size_t size_of(Scalar s) {
  switch (s) {
    case Scalar::kInt8:
    case Scalar::kUint8:
      return 1;
    case Scalar::kInt16:
    case Scalar::kUint16:
      return 2;
    case Scalar::kInt32:
    case Scalar::kUint32:
    case Scalar::kFloat32:
      return 4;
    case Scalar::kFloat64:
      return 8;
  }
  return 8;
}

bool is_integer(Scalar s) {
  return s != Scalar::kFloat32 && s != Scalar::kFloat64;
}

struct Property {
  std::string name;
  Scalar type = Scalar::kFloat32;
  bool list = false;
  Scalar count_type = Scalar::kUint8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { kAscii, kLittle, kBig };

// Reads the values of the body one at a time, in either encoding. A value is a double: every
// PLY scalar type converts to it exactly.
class Values {
 public:
  Values(std::string_view body, Format format) : body_(body), format_(format) {}

  // Empty on success, else the problem.
  std::string next(Scalar type, double& value) {
    if (format_ == Format::kAscii) return next_text(type, value);
    const std::size_t n = size_of(type);
    if (n > body_.size() - at_) return "the file ends in the middle of the data";
    unsigned char b[8];
    std::memcpy(b, body_.data() + at_, n);
    at_ += n;
    if ((format_ == Format::kBig) != (std::endian::native == std::endian::big)) {
      std::reverse(b, b + n);
    }
    switch (type) {
      case Scalar::kInt8:
        value = double(std::bit_cast<std::int8_t>(b[0]));
        break;
      case Scalar::kUint8:
        value = double(b[0]);
        break;
      case Scalar::kInt16:
        value = double(load<std::int16_t>(b));
        break;
      case Scalar::kUint16:
        value = double(load<std::uint16_t>(b));
        break;
      case Scalar::kInt32:
        value = double(load<std::int32_t>(b));
        break;
      case Scalar::kUint32:
        value = double(load<std::uint32_t>(b));
        break;
      case Scalar::kFloat32:
        value = double(load<float>(b));
        break;
      case Scalar::kFloat64:
        value = load<double>(b);
        break;
    }
    return {};
  }

  std::size_t remaining() const { return body_.size() - at_; }

 private:
  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }

  std::string next_text(Scalar type, double& value) {
    while (at_ < body_.size() && is_space(body_[at_])) ++at_;
    if (at_ == body_.size()) return "the file ends in the middle of the data";
    const std::size_t begin = at_;
    while (at_ < body_.size() && !is_space(body_[at_])) ++at_;
    const std::string_view token = body_.substr(begin, at_ - begin);
    if (is_integer(type)) {
      const auto v = parse_int<std::int64_t>(token);
      if (!v) return quote(token) + " is not an integer";
      value = double(*v);
    } else {
      const auto v = parse_real(token);
      if (!v) return quote(token) + " is not a number";
      value = *v;
    }
    return {};
  }

  std::string_view body_;
  Format format_;
  std::size_t at_ = 0;
};

}  // namespace

namespace {

// One header line after 'ply': a format, element or property declaration.
std::string read_ply_header_line(const std::vector<std::string_view>& t,
                                 std::optional<Format>& format, std::vector<Element>& elements) {
  if (t[0] == "format") {
    if (t.size() < 2) return "'format' names no encoding";
    if (t[1] == "ascii") {
      format = Format::kAscii;
    } else if (t[1] == "binary_little_endian") {
      format = Format::kLittle;
    } else if (t[1] == "binary_big_endian") {
      format = Format::kBig;
    } else {
      return "unknown encoding " + quote(t[1]);
    }
  } else if (t[0] == "element") {
    if (t.size() != 3) return "expected 'element <name> <count>'";
    const auto count = parse_int<std::uint64_t>(t[2]);
    if (!count) return "the count " + quote(t[2]) + " is not a non-negative integer";
    elements.push_back({std::string(t[1]), *count, {}});
  } else if (t[0] == "property") {
    if (elements.empty()) return "a property before any element";
    Property p;
    if (t.size() == 5 && t[1] == "list") {
      const auto count_type = scalar_of(t[2]);
      const auto item_type = scalar_of(t[3]);
      if (!count_type || !item_type || !is_integer(*count_type)) {
        return "unknown list types " + quote(t[2]) + " " + quote(t[3]);
      }
      p = {std::string(t[4]), *item_type, true, *count_type};
    } else if (t.size() == 3) {
      const auto type = scalar_of(t[1]);
      if (!type) return "unknown type " + quote(t[1]);
      p = {std::string(t[2]), *type, false, Scalar::kUint8};
    } else {
      return "expected 'property <type> <name>' or 'property list ...'";
    }
    for (const Property& q : elements.back().properties) {
      if (q.name == p.name) {
        return "property " + quote(p.name) + " appears twice in element " +
               quote(elements.back().name) + "; the header is wrong";
      }
    }
    elements.back().properties.push_back(p);
  } else {
    return "unknown keyword " + quote(t[0]);
  }
  return {};
}

std::string read_ply_header(Lines& lines, std::optional<Format>& format,
                            std::vector<Element>& elements) {
  std::string_view line;
  if (!lines.next(line) || trim(line) != "ply") return "it does not start with the line 'ply'";
  while (lines.next(line)) {
    const std::vector<std::string_view> t = split(line);
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (t[0] == "end_header") {
      if (!format) return "the header has no 'format' line";
      return {};
    }
    if (std::string problem = read_ply_header_line(t, format, elements); !problem.empty()) {
      return "header line " + std::to_string(lines.number()) + ": " + problem;
    }
  }
  return "the header has no 'end_header' line";
}

// Every record takes at least one byte per scalar (binary) or two characters per value
// (text): counts the rest of the file cannot hold are refused before any allocation, and a
// record can never take zero bytes, so time is bounded by the file size too.
std::string check_ply_counts(const std::vector<Element>& elements, Format format,
                             std::uint64_t left) {
  std::uint64_t needed = 0;
  for (const Element& e : elements) {
    if (e.count > 0 && e.properties.empty()) {
      return "element '" + e.name + "' has no properties, so its " + std::to_string(e.count) +
             " records cannot be read; the header is wrong";
    }
    std::uint64_t record = 0;
    for (const Property& p : e.properties) {
      record += format == Format::kAscii ? 2 : size_of(p.list ? p.count_type : p.type);
    }
    if (e.count > kMaxIndexable || (record > 0 && e.count > (left - needed) / record)) {
      return "the header claims " + std::to_string(e.count) + " '" + e.name +
             "' records, but only " + std::to_string(left) +
             " bytes of data follow it; the header is wrong or the file is truncated";
    }
    needed += e.count * record;
  }
  return {};
}

// Which properties of an element the mesh needs: x, y, z of the first 'vertex' element, the
// index list of a 'face' element; -1 where absent.
struct PlyRoles {
  bool is_vertex = false;
  bool is_face = false;
  int xyz[3] = {-1, -1, -1};
  int nxyz[3] = {-1, -1, -1};  // the vertex normal, kept only when all three are there
  int indices = -1;
  bool has_normals() const { return nxyz[0] >= 0 && nxyz[1] >= 0 && nxyz[2] >= 0; }
};

PlyRoles ply_roles(const Element& e, bool saw_vertices) {
  PlyRoles r;
  r.is_vertex = e.name == "vertex" && !saw_vertices;
  r.is_face = e.name == "face";
  for (std::size_t i = 0; i < e.properties.size(); ++i) {
    const Property& p = e.properties[i];
    if (r.is_vertex && !p.list) {
      if (p.name == "x") r.xyz[0] = int(i);
      if (p.name == "y") r.xyz[1] = int(i);
      if (p.name == "z") r.xyz[2] = int(i);
      if (p.name == "nx") r.nxyz[0] = int(i);
      if (p.name == "ny") r.nxyz[1] = int(i);
      if (p.name == "nz") r.nxyz[2] = int(i);
    }
    if (r.is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      r.indices = int(i);
    }
  }
  return r;
}

// One list property of a record; its items are kept in out.corners when `keep`.
std::string read_ply_list(Values& values, const Property& prop, Format format, bool keep,
                          RawPolygons& out) {
  double value = 0;
  if (std::string problem = values.next(prop.count_type, value); !problem.empty()) {
    return problem;
  }
  // Checked against what is left before the items are read, so a forged count costs
  // neither memory nor time.
  const std::uint64_t per_item = format == Format::kAscii ? 2 : size_of(prop.type);
  if (value < 0 || value > double(values.remaining() / per_item + 1)) {
    return "list '" + prop.name + "' claims " + std::to_string(value) +
           " items, more than the rest of the file holds";
  }
  const auto n = std::uint64_t(value);
  for (std::uint64_t k = 0; k < n; ++k) {
    if (std::string problem = values.next(prop.type, value); !problem.empty()) return problem;
    if (keep) {
      if (!(std::abs(value) < 9.2e18) || value != std::floor(value)) {
        return "vertex index " + std::to_string(value) + " is not an integer";
      }
      out.corners.push_back(std::int64_t(value));
    }
  }
  return {};
}

std::string read_ply_element(Values& values, const Element& e, const PlyRoles& roles, Format format,
                             RawPolygons& out) {
  if (roles.is_vertex) out.positions.reserve(e.count);
  const bool normals = roles.is_vertex && roles.has_normals();
  if (normals) out.normals.reserve(e.count);
  if (roles.is_face) out.face_offsets.reserve(out.face_offsets.size() + e.count);
  for (std::uint64_t r = 0; r < e.count; ++r) {
    const auto where = [&] { return "'" + e.name + "' record " + std::to_string(r) + ": "; };
    float p[3] = {0, 0, 0}, n[3] = {0, 0, 0};
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& prop = e.properties[i];
      std::string problem;
      if (prop.list) {
        problem =
            read_ply_list(values, prop, format, roles.is_face && roles.indices == int(i), out);
      } else {
        double value = 0;
        problem = values.next(prop.type, value);
        for (int k = 0; k < 3; ++k) {
          if (roles.is_vertex && roles.xyz[k] == int(i)) p[k] = float(value);
          if (normals && roles.nxyz[k] == int(i)) n[k] = float(value);
        }
      }
      if (!problem.empty()) return where() + problem;
    }
    if (roles.is_vertex) out.positions.emplace_back(p[0], p[1], p[2]);
    if (normals) out.normals.emplace_back(n[0], n[1], n[2]);
    if (roles.is_face && roles.indices >= 0) out.face_offsets.push_back(out.corners.size());
  }
  return {};
}

}  // namespace

std::string read_ply(std::string_view bytes, RawPolygons& out) {
  Lines lines(bytes);
  std::optional<Format> format;
  std::vector<Element> elements;
  if (std::string problem = read_ply_header(lines, format, elements); !problem.empty()) {
    return problem;
  }
  const std::uint64_t left = lines.remaining();
  if (std::string problem = check_ply_counts(elements, *format, left); !problem.empty()) {
    return problem;
  }
  Values values(bytes.substr(bytes.size() - left), *format);
  bool saw_vertices = false;
  for (const Element& e : elements) {
    const PlyRoles roles = ply_roles(e, saw_vertices);
    if (roles.is_vertex) {
      if (roles.xyz[0] < 0 || roles.xyz[1] < 0 || roles.xyz[2] < 0) {
        return "element 'vertex' lacks one of the scalar properties x, y, z";
      }
      saw_vertices = true;
    }
    if (std::string problem = read_ply_element(values, e, roles, *format, out); !problem.empty()) {
      return problem;
    }
  }
  if (!saw_vertices) return "the header declares no 'vertex' element";
  return {};
}

// --- STL ------------------------------------------------------------------------------------

namespace {

// Each triangle becomes three new positions (STL shares none); the loader welds them.
std::string add_stl_triangle(const float (&p)[3][3], std::uint64_t t, RawPolygons& out) {
  for (const auto& corner : p) {
    for (float x : corner) {
      if (!std::isfinite(x)) {
        return "triangle " + std::to_string(t) + " has a non-finite coordinate (" +
               std::to_string(x) + "); fix or remove it";
      }
    }
  }
  for (const auto& corner : p) {
    out.corners.push_back(std::int64_t(out.positions.size()));
    out.positions.emplace_back(corner[0], corner[1], corner[2]);
  }
  out.face_offsets.push_back(out.corners.size());
  return {};
}

}  // namespace

std::string read_stl_binary(std::string_view bytes, RawPolygons& out) {
  constexpr std::size_t kHeader = 84, kRecord = 50;
  if (bytes.size() < kHeader) return "shorter than the 84-byte binary STL header";
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);
  if ((bytes.size() - kHeader) / kRecord < count) {
    return "its header claims " + std::to_string(count) + " triangles, more than its " +
           std::to_string(bytes.size()) + " bytes hold";
  }
  out.positions.reserve(3 * std::size_t(count));
  out.corners.reserve(3 * std::size_t(count));
  out.face_offsets.reserve(count + 1);
  for (std::uint32_t t = 0; t < count; ++t) {
    float p[3][3];
    // Little-endian floats after the facet normal, which is recomputed and so skipped.
    std::memcpy(p, bytes.data() + kHeader + kRecord * t + 12, sizeof p);
    if (std::string problem = add_stl_triangle(p, t, out); !problem.empty()) return problem;
  }
  return {};
}

// solid NAME / facet normal N N N / outer loop / vertex X Y Z (three) / endloop / endfacet /
// endsolid. Keywords are checked in order, and every vertex needs three numbers: a reader that
// skips what it cannot parse leaves coordinates unset.
std::string read_stl_ascii(std::string_view bytes, RawPolygons& out) {
  Lines lines(bytes);
  std::string_view line;
  std::vector<std::string_view> t;
  const auto where = [&] { return "line " + std::to_string(lines.number()) + ": "; };
  const auto next = [&] {
    while (lines.next(line)) {
      t = split(line);
      if (!t.empty()) return true;
    }
    return false;
  };
  if (!next() || t[0] != "solid") return "it does not start with 'solid'; not an ASCII STL file";
  std::uint64_t triangles = 0;
  while (next()) {
    if (t[0] == "endsolid") {
      if (next() && t[0] == "solid") continue;  // several solids in one file
      return triangles == 0 ? "it holds no facets" : std::string();
    }
    if (t[0] != "facet") return where() + "expected 'facet' or 'endsolid', found " + quote(t[0]);
    if (!next() || t[0] != "outer" || t.size() != 2 || t[1] != "loop")
      return where() + "expected 'outer loop' after 'facet'";
    float p[3][3];
    for (int c = 0; c < 3; ++c) {
      if (!next() || t[0] != "vertex")
        return where() + "expected the facet's vertex " + std::to_string(c + 1) + " of 3";
      if (t.size() != 4) {
        return where() + "'vertex' needs three coordinates, found " + std::to_string(t.size() - 1);
      }
      for (int k = 0; k < 3; ++k) {
        const std::optional<double> x = parse_real(t[1 + k]);
        if (!x) return where() + quote(t[1 + k]) + " is not a number";
        if (!std::isfinite(float(*x))) return where() + quote(t[1 + k]) + " is not a finite float";
        p[c][k] = float(*x);
      }
    }
    if (!next() || t[0] != "endloop") return where() + "expected 'endloop' after three vertices";
    if (!next() || t[0] != "endfacet") return where() + "expected 'endfacet'";
    if (std::string problem = add_stl_triangle(p, triangles, out); !problem.empty())
      return where() + problem;
    ++triangles;
  }
  return "it ends without 'endsolid'; the file is truncated";
}

// --- OBJ pre-pass -----------------------------------------------------------------------------

std::string check_obj_faces(std::string_view bytes) {
  Lines lines(bytes);
  std::string_view line;
  while (lines.next(line)) {
    const std::vector<std::string_view> t = split(line);
    if (t.empty() || t[0] != "f") continue;
    const std::string where = "line " + std::to_string(lines.number()) + ": ";
    if (t.size() == 1) return where + "a face ('f') with no corners";
    for (std::size_t c = 1; c < t.size(); ++c) {
      // v, v/vt, v//vn, v/vt/vn: the vertex index is required, the others may be empty.
      std::string_view rest = t[c];
      int parts = 0;
      bool ok = true;
      while (ok) {
        const std::size_t slash = rest.find('/');
        const std::string_view part = rest.substr(0, slash);
        const auto v = parse_int<int>(part);
        if (parts == 0) {
          ok = v.has_value() && *v != 0;
        } else {
          ok = part.empty() || v.has_value();
        }
        ++parts;
        if (slash == std::string_view::npos) break;
        rest.remove_prefix(slash + 1);
      }
      if (!ok || parts > 3) {
        return where + "face corner " + quote(t[c]) +
               " is not v, v/vt, v//vn or v/vt/vn with v a non-zero vertex number";
      }
    }
  }
  return {};
}

void read_obj_normals(std::string_view bytes, ObjNormals& out) {
  Lines lines(bytes);
  std::string_view line;
  std::int64_t vertex_records = 0;
  bool normals_ok = true;
  while (lines.next(line)) {
    const std::vector<std::string_view> t = split(line);
    if (t.empty()) continue;
    if (t[0] == "v") {
      ++vertex_records;
    } else if (t[0] == "vn") {
      std::optional<double> c[3];
      for (int k = 0; k < 3; ++k)
        c[k] = t.size() > std::size_t(k + 1) ? parse_real(t[k + 1]) : std::nullopt;
      if (!c[0] || !c[1] || !c[2]) normals_ok = false;
      if (normals_ok) out.normals.emplace_back(float(*c[0]), float(*c[1]), float(*c[2]));
    } else if (t[0] == "f" && t.size() > 1) {
      const auto normal_count = std::int64_t(out.normals.size());
      for (std::size_t c = 1; c < t.size(); ++c) {
        const std::string_view corner = t[c];
        const std::size_t first = corner.find('/');
        const std::int64_t v = parse_int<int>(corner.substr(0, first)).value_or(0);
        out.vertices.push_back(v > 0 ? v - 1 : vertex_records + v);
        std::int64_t n = -1;
        if (first != std::string_view::npos) {
          const std::size_t second = corner.find('/', first + 1);
          if (second != std::string_view::npos) {
            if (const auto k = parse_int<int>(corner.substr(second + 1)); k && *k != 0) {
              n = *k > 0 ? *k - 1 : normal_count + *k;
            }
          }
        }
        out.normal_of_corner.push_back(n);
      }
      out.face_offsets.push_back(out.vertices.size());
    }
  }
}

void blank_obj_material_libraries(std::string& text) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find_first_of("\r\n", start);
    if (end == std::string::npos) end = text.size();
    std::size_t first = text.find_first_not_of(" \t", start);
    if (first < end && text.compare(first, 6, "mtllib") == 0 &&
        (first + 6 == end || text[first + 6] == ' ' || text[first + 6] == '\t')) {
      for (std::size_t i = first; i < end; ++i) text[i] = ' ';
    }
    start = end + 1;
  }
}

std::string normalise_obj_text(std::string& text) {
  std::size_t line = 1, start = 0;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    if (i < text.size() && text[i] == '\r' && (i + 1 == text.size() || text[i + 1] != '\n'))
      text[i] = '\n';
    if (i == text.size() || text[i] == '\n') {
      if (i - start > kMaxObjLineBytes) {
        return "line " + std::to_string(line) + " has " + std::to_string(i - start) +
               " bytes, over the limit of " + std::to_string(kMaxObjLineBytes) +
               " for one OBJ statement; the file is damaged";
      }
      ++line;
      start = i + 1;
    }
  }
  return {};
}

}  // namespace meshes::detail
