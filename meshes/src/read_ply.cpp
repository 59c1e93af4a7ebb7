// The PLY reader of read_strict.h: ASCII and binary bodies of either byte order, with every
// element's size checked against the bytes that remain before anything is allocated.
#include "read_strict.h"
#include "text_tokens.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>

namespace meshes::detail {

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

template <class T>
double load_as_double(const unsigned char* b) {
  T v;
  std::memcpy(&v, b, sizeof v);
  return double(v);
}

// Bytes and a loader per Scalar, in its order.
struct ScalarType {
  std::size_t bytes;
  double (*load)(const unsigned char*);
};
constexpr ScalarType kScalarTypes[] = {
    {1, load_as_double<std::int8_t>},  {1, load_as_double<std::uint8_t>},
    {2, load_as_double<std::int16_t>}, {2, load_as_double<std::uint16_t>},
    {4, load_as_double<std::int32_t>}, {4, load_as_double<std::uint32_t>},
    {4, load_as_double<float>},        {8, load_as_double<double>}};

std::size_t size_of(Scalar s) {
  return kScalarTypes[int(s)].bytes;
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
    unsigned char b[8];
    const std::size_t n = std::min(size_of(type), sizeof b);  // 1 to 8; bounded for the compiler
    if (n > body_.size() - at_) return "the file ends in the middle of the data";
    std::memcpy(b, body_.data() + at_, n);
    at_ += n;
    if ((format_ == Format::kBig) != (std::endian::native == std::endian::big)) {
      std::reverse(b, b + n);
    }
    value = kScalarTypes[int(type)].load(b);
    return {};
  }

  std::size_t remaining() const { return body_.size() - at_; }

 private:
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

}  // namespace meshes::detail
