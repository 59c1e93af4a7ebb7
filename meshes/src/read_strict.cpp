#include "read_strict.h"
#include "text_tokens.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>

namespace meshes::detail {

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
