// meshes/asset_guard.cpp: the glTF and GLB checks in front of Assimp (see asset_guard.h; the
// 3DS check is asset_guard_3ds.cpp).
//
// Every check reports by throwing Refusal (guard_refusal.h); the entry points turn it into
// the returned string. Sizes are compared in 64 bits after bounding each factor, so no
// claimed count can overflow a comparison.
#include "asset_guard.h"
#include "guard_refusal.h"

#include "common/base64.h"
#include "common/input_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <optional>
#include <string_view>
#include <vector>

namespace meshes::detail {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// --- glTF JSON ------------------------------------------------------------------------------

// Assimp's JSON parser recurses once per nesting level; this scan does not.
void check_json_depth(std::string_view text) {
  int depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth) {
        refuse("its JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels (at byte " +
               std::to_string(i) +
               "); no glTF file needs that, the file "
               "is damaged or hostile");
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

const json& array_at(const json& root, const char* key) {
  static const json empty = json::array();
  const auto it = root.find(key);
  if (it == root.end()) return empty;
  if (!it->is_array()) refuse(std::string("'") + key + "' is not an array; the file is damaged");
  return *it;
}

// A non-negative integer member of `object`, or `fallback` when it is absent.
std::uint64_t count_of(const json& object, const char* key, const std::string& where,
                       std::optional<std::uint64_t> fallback = std::nullopt) {
  const auto it = object.find(key);
  if (it == object.end()) {
    if (fallback) return *fallback;
    refuse(where + " has no '" + key + "'; the file is damaged");
  }
  if (!it->is_number_unsigned()) {
    refuse(where + "'s '" + key + "' is not a non-negative integer; the file is damaged");
  }
  return it->get<std::uint64_t>();
}

std::uint64_t index_into(const json& object, const char* key, std::size_t size,
                         const std::string& where, const char* what) {
  const std::uint64_t i = count_of(object, key, where);
  if (i >= size) {
    refuse(where + " names " + what + " " + std::to_string(i) + ", but the file has " +
           std::to_string(size) + "; the file is damaged");
  }
  return i;
}

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// URIs may %-escape a '.' or '/', so the escape check looks at the decoded path.
std::string percent_decoded(std::string_view uri, const std::string& where) {
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] != '%') {
      out += uri[i];
      continue;
    }
    const int hi = i + 2 < uri.size() ? hex_digit(uri[i + 1]) : -1;
    const int lo = hi >= 0 ? hex_digit(uri[i + 2]) : -1;
    if (lo < 0) refuse(where + " has a malformed %-escape in its URI; the file is damaged");
    out += char(hi * 16 + lo);
    i += 2;
  }
  return out;
}

constexpr std::size_t kMaxDataUriHeader = 100;

// The decoded size of a base64 data URI. Its characters are checked here because Assimp's
// decoder leaks the buffer it was filling when it meets a bad one.
std::uint64_t data_uri_bytes(std::string_view uri, const std::string& where) {
  const std::size_t comma = uri.find(',');
  if (comma == std::string_view::npos || uri.substr(0, comma).find(";base64") == uri.npos) {
    refuse(where + " has a data URI that is not base64 ('data:...;base64,...'); re-export it");
  }
  // Assimp's data URI parser keeps the offsets of the media type, parameters and payload in
  // chars: past 127 they wrap, and it reads before the string.
  if (comma > kMaxDataUriHeader) {
    refuse(where + "'s data URI has a header of " + std::to_string(comma) +
           " characters before "
           "its ',' (at most " +
           std::to_string(kMaxDataUriHeader) + " are read); re-export it");
  }
  const std::string_view payload = uri.substr(comma + 1);
  if (payload.size() / 4 * 3 > kMaxDataUriBytes) {
    refuse(where + " embeds " + std::to_string(payload.size() / 4 * 3) +
           " bytes in a data URI, over the " + std::to_string(kMaxDataUriBytes >> 20) +
           " MiB limit; store them in a .bin or .glb");
  }
  const auto is_base64 = [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' ||
           c == '/';
  };
  std::size_t padding = 0;
  while (padding < 2 && padding < payload.size() && payload[payload.size() - 1 - padding] == '=') {
    ++padding;
  }
  for (std::size_t i = 0; i + padding < payload.size(); ++i) {
    if (!is_base64(payload[i])) {
      refuse(where + "'s data URI has a character that is not base64 at offset " +
             std::to_string(comma + 1 + i) + "; the file is damaged");
    }
  }
  if (payload.size() % 4 != 0) {
    refuse(where + "'s data URI is not a whole number of base64 quads; the file is damaged");
  }
  return payload.size() / 4 * 3 - padding;
}

// The bytes a buffer or image URI stands for: a data URI's decoded size, or the size of a
// file next to the glTF file. Refuses anything that leaves the file's folder.
// Images are never opened for geometry (Assimp only records external image paths), so a
// missing image is no error; leaving the folder still is.
std::uint64_t uri_bytes(const std::string& uri, const fs::path& folder, const std::string& where,
                        bool must_exist = true) {
  if (uri.rfind("data:", 0) == 0) return data_uri_bytes(uri, where);
  const std::string path = percent_decoded(uri, where);
  const fs::path relative(path);
  bool escapes = path.empty() || path.find(':') != std::string::npos ||
                 path.find('\\') != std::string::npos || relative.has_root_path();
  for (const fs::path& part : relative) escapes = escapes || part == "..";
  if (escapes) {
    refuse(where + " refers to '" + uri +
           "', outside the file's folder (or another scheme); "
           "only files beside the .gltf are read: copy them there and use a relative URI");
  }
  if (!must_exist) return 0;
  std::error_code ec;
  const fs::path target = folder / relative;
  if (!fs::is_regular_file(target, ec)) {
    refuse(where + " refers to '" + uri + "', which is not a file beside the .gltf; copy it there");
  }
  const std::uint64_t size = fs::file_size(target, ec);
  if (ec || size > kMaxAssetBytes) {
    refuse(where + "'s file '" + uri + "' is over the " + std::to_string(kMaxAssetBytes >> 20) +
           " MiB limit (or unreadable)");
  }
  return size;
}

// Where a buffer's bytes are, so that index values can be read: the .glb's binary chunk, a
// base64 data URI, or a file beside the .gltf.
struct BufferSource {
  std::uint64_t length = 0;   // byteLength, checked against what the source holds
  std::string_view data_uri;  // the whole URI for an embedded buffer
  fs::path file;              // the checked (percent-decoded) path of an external buffer
  bool glb_chunk = false;
};

std::vector<BufferSource> check_buffers(const json& root, const fs::path& folder,
                                        const std::optional<std::string_view>& glb_bin,
                                        ReferencedFiles& referenced) {
  std::vector<BufferSource> sources;
  const json& buffers = array_at(root, "buffers");
  for (std::size_t b = 0; b < buffers.size(); ++b) {
    const std::string where = "buffer " + std::to_string(b);
    const json& buffer = buffers[b];
    if (!buffer.is_object()) refuse(where + " is not an object; the file is damaged");
    BufferSource source;
    source.length = count_of(buffer, "byteLength", where);
    std::uint64_t available = 0;
    if (const auto uri = buffer.find("uri"); uri != buffer.end()) {
      if (!uri->is_string()) refuse(where + "'s uri is not a string; the file is damaged");
      const std::string& text = uri->get_ref<const std::string&>();
      available = uri_bytes(text, folder, where);
      if (text.rfind("data:", 0) == 0) {
        source.data_uri = text;
      } else {
        // Assimp asks for the URI as written; it is given the file checked here.
        source.file = folder / percent_decoded(text, where);
        referenced.push_back({text, source.file});
      }
    } else if (b == 0 && glb_bin) {
      available = glb_bin->size();
      source.glb_chunk = true;
    } else {
      refuse(where + " has no uri and is not the .glb's binary chunk; the file is damaged");
    }
    if (source.length > available) {
      refuse(where + " claims " + std::to_string(source.length) + " bytes, but its data holds " +
             std::to_string(available) + "; the file or its .bin is truncated");
    }
    sources.push_back(std::move(source));
  }
  return sources;
}

std::vector<std::uint64_t> check_buffer_views(const json& root,
                                              const std::vector<BufferSource>& sources) {
  std::vector<std::uint64_t> buffers;
  for (const BufferSource& source : sources) buffers.push_back(source.length);
  std::vector<std::uint64_t> lengths;
  const json& views = array_at(root, "bufferViews");
  for (std::size_t v = 0; v < views.size(); ++v) {
    const std::string where = "bufferView " + std::to_string(v);
    const json& view = views[v];
    if (!view.is_object()) refuse(where + " is not an object; the file is damaged");
    const std::uint64_t b = index_into(view, "buffer", buffers.size(), where, "buffer");
    const std::uint64_t offset = count_of(view, "byteOffset", where, 0);
    const std::uint64_t length = count_of(view, "byteLength", where);
    if (offset > buffers[b] || length > buffers[b] - offset) {
      refuse(where + " spans bytes [" + std::to_string(offset) + ", +" + std::to_string(length) +
             ") of buffer " + std::to_string(b) + ", which has " + std::to_string(buffers[b]) +
             "; the file is damaged");
    }
    const std::uint64_t stride = count_of(view, "byteStride", where, 0);
    if (stride != 0 && (stride < 4 || stride > 252)) {
      refuse(where + " has byteStride " + std::to_string(stride) + ", outside glTF's 4..252");
    }
    lengths.push_back(length);
  }
  return lengths;
}

// Bytes of one element of an accessor, 0 for an unknown type.
std::uint64_t element_bytes(std::uint64_t component_type, const std::string& type) {
  std::uint64_t component = 0;
  if (component_type == 5120 || component_type == 5121) component = 1;
  if (component_type == 5122 || component_type == 5123) component = 2;
  if (component_type == 5125 || component_type == 5126) component = 4;
  std::uint64_t n = 0;
  if (type == "SCALAR") n = 1;
  if (type == "VEC2") n = 2;
  if (type == "VEC3") n = 3;
  if (type == "VEC4" || type == "MAT2") n = 4;
  if (type == "MAT3") n = 9;
  if (type == "MAT4") n = 16;
  return component * n;
}

void check_accessors(const json& root, const std::vector<std::uint64_t>& views) {
  const json& accessors = array_at(root, "accessors");
  const json& view_list = array_at(root, "bufferViews");
  for (std::size_t a = 0; a < accessors.size(); ++a) {
    const std::string where = "accessor " + std::to_string(a);
    const json& accessor = accessors[a];
    if (!accessor.is_object()) refuse(where + " is not an object; the file is damaged");
    if (accessor.contains("sparse")) {
      refuse(where + " is sparse, which is not supported; export without sparse accessors");
    }
    if (!accessor.contains("bufferView")) {
      refuse(where + " has no bufferView (implicit zeros), which is not supported; re-export");
    }
    const std::uint64_t v = index_into(accessor, "bufferView", views.size(), where, "bufferView");
    const auto type = accessor.find("type");
    const std::uint64_t element =
        element_bytes(count_of(accessor, "componentType", where),
                      type != accessor.end() && type->is_string() ? type->get<std::string>() : "");
    if (element == 0) refuse(where + " has an unknown type or componentType; damaged");
    const std::uint64_t count = count_of(accessor, "count", where);
    const std::uint64_t offset = count_of(accessor, "byteOffset", where, 0);
    const std::uint64_t stride = count_of(view_list[v], "byteStride", where, 0);
    const std::uint64_t step = std::max(stride, element);
    // count <= view length keeps the product below 2^40.
    if (count == 0 || count > views[v] || offset > views[v] ||
        (count - 1) * step + element > views[v] - offset) {
      refuse(where + " claims " + std::to_string(count) + " elements of " +
             std::to_string(element) + " bytes from byte " + std::to_string(offset) +
             " of bufferView " + std::to_string(v) + ", which has " + std::to_string(views[v]) +
             " bytes; the file is damaged");
    }
  }
}

void check_meshes(const json& root) {
  const json& accessor_list = array_at(root, "accessors");
  const std::size_t accessors = accessor_list.size();
  const json& meshes = array_at(root, "meshes");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const std::string where = "mesh " + std::to_string(m);
    if (!meshes[m].is_object()) refuse(where + " is not an object; the file is damaged");
    const json& primitives = array_at(meshes[m], "primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const std::string at = where + " primitive " + std::to_string(p);
      const json& primitive = primitives[p];
      if (!primitive.is_object()) refuse(at + " is not an object; the file is damaged");
      if (!array_at(primitive, "targets").empty()) {
        refuse(at +
               " has morph targets, which are not supported; apply them (export the "
               "mesh in one pose, without shape keys)");
      }
      const auto attributes = primitive.find("attributes");
      if (attributes == primitive.end() || !attributes->is_object() ||
          !attributes->contains("POSITION")) {
        refuse(at + " has no POSITION attribute; the file is damaged");
      }
      for (const auto& [name, value] : attributes->items()) {
        if (!value.is_number_unsigned() || value.get<std::uint64_t>() >= accessors) {
          refuse(at + "'s attribute " + name + " names no accessor; the file is damaged");
        }
      }
      // Each accessor must have the type its role reads: Assimp trusts the roles, so float
      // positions named as indices were read as indices (and crashed the line-loop path).
      const auto expect_role = [&](std::uint64_t a, const char* role, const char* type,
                                   std::initializer_list<std::uint64_t> component_types,
                                   const char* wanted) {
        const json& accessor = accessor_list[a];
        const auto t = accessor.find("type");
        const auto c = accessor.find("componentType");
        const bool type_ok = t != accessor.end() && t->is_string() && t->get<std::string>() == type;
        bool component_ok = false;
        if (c != accessor.end() && c->is_number_unsigned())
          for (std::uint64_t allowed : component_types)
            component_ok |= c->get<std::uint64_t>() == allowed;
        if (!type_ok || !component_ok) {
          refuse(at + "'s " + role + " accessor " + std::to_string(a) + " is not " + wanted +
                 "; the file is damaged");
        }
      };
      for (const char* name : {"POSITION", "NORMAL"}) {
        const auto value = attributes->find(name);
        if (value != attributes->end())
          expect_role(value->get<std::uint64_t>(), name, "VEC3", {5126}, "VEC3 of floats");
      }
      if (primitive.contains("indices")) {
        const std::uint64_t a = index_into(primitive, "indices", accessors, at, "accessor");
        expect_role(a, "indices", "SCALAR", {5121, 5123, 5125},
                    "SCALAR of unsigned bytes, shorts or ints");
      }
      if (const auto mode = primitive.find("mode"); mode != primitive.end()) {
        if (!mode->is_number_unsigned() || mode->get<std::uint64_t>() > 6) {
          refuse(at + " has mode " + mode->dump() +
                 ", not one of glTF's primitive modes 0 to 6; the file is damaged");
        }
      }
    }
  }
}

// Node children must form a forest no deeper than kMaxNodeDepth: Assimp converts the node
// tree recursively, and a node shared by two parents would be instanced once per path.
void check_nodes(const json& root) {
  const json& nodes = array_at(root, "nodes");
  const std::size_t mesh_count = array_at(root, "meshes").size();
  std::vector<std::int64_t> parent(nodes.size(), -1);
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    const std::string where = "node " + std::to_string(n);
    if (!nodes[n].is_object()) refuse(where + " is not an object; the file is damaged");
    if (nodes[n].contains("skin")) {
      refuse(where +
             " is skinned (bones), which is not supported; export the mesh in its "
             "bind pose without the armature");
    }
    if (nodes[n].contains("mesh")) index_into(nodes[n], "mesh", mesh_count, where, "mesh");
    const json& children = array_at(nodes[n], "children");
    for (const json& c : children) {
      if (!c.is_number_unsigned() || c.get<std::uint64_t>() >= nodes.size()) {
        refuse(where + " has a child that is no node; the file is damaged");
      }
      const std::size_t child = c.get<std::size_t>();
      if (parent[child] != -1 || child == n) {
        refuse("node " + std::to_string(child) +
               " has two parents or is its own child; the "
               "node hierarchy must be a tree");
      }
      parent[child] = std::int64_t(n);
    }
  }
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    int depth = 0;
    for (std::int64_t at = std::int64_t(n); at != -1; at = parent[std::size_t(at)]) {
      if (++depth > kMaxNodeDepth) {
        refuse("node " + std::to_string(n) + " is nested deeper than " +
               std::to_string(kMaxNodeDepth) + " levels (or in a cycle); flatten the hierarchy");
      }
    }
  }
}

// Reads each buffer once, when an index accessor needs it.
class BufferBytes {
 public:
  BufferBytes(const std::vector<BufferSource>& sources, std::string_view glb_bin)
      : sources_(sources), glb_bin_(glb_bin), owned_(sources.size()) {}

  std::string_view operator()(std::size_t b) {
    const BufferSource& source = sources_[b];
    if (source.glb_chunk) return glb_bin_;
    std::optional<std::string>& bytes = owned_[b];
    if (!bytes)
      bytes = source.file.empty()
                  ? common::base64_decode(source.data_uri.substr(source.data_uri.find(',') + 1))
                  : file_bytes(source);
    // A file that shrank since it was measured is as damaged as a short one.
    if (bytes->size() < source.length) {
      refuse("buffer " + std::to_string(b) + " holds " + std::to_string(bytes->size()) +
             " bytes, fewer than its byteLength " + std::to_string(source.length) +
             " (did the file change while it was read?)");
    }
    return *bytes;
  }

 private:
  static std::string file_bytes(const BufferSource& source) {
    common::InputFile in = common::open_input_file(source.file, kMaxAssetBytes);
    if (in.file == nullptr) refuse("its buffer file " + source.file.string() + " " + in.problem);
    std::string bytes(in.size, '\0');
    bytes.resize(std::fread(bytes.data(), 1, bytes.size(), in.file));
    return bytes;
  }

  const std::vector<BufferSource>& sources_;
  std::string_view glb_bin_;
  std::vector<std::optional<std::string>> owned_;
};

// Every index must name a vertex of its primitive: Assimp drops a face with an index out of
// range without a word, which leaves a hole where the file is damaged.
void check_index_values(const json& root, BufferBytes& buffers) {
  const json& accessors = array_at(root, "accessors");
  const json& views = array_at(root, "bufferViews");
  const json& meshes = array_at(root, "meshes");
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const json& primitives = array_at(meshes[m], "primitives");
    for (std::size_t p = 0; p < primitives.size(); ++p) {
      const json& primitive = primitives[p];
      if (!primitive.contains("indices")) continue;
      const std::string at = "mesh " + std::to_string(m) + " primitive " + std::to_string(p);
      const std::uint64_t vertices =
          accessors[primitive["attributes"]["POSITION"].get<std::size_t>()]["count"]
              .get<std::uint64_t>();
      const json& accessor = accessors[primitive["indices"].get<std::size_t>()];
      const json& view = views[accessor["bufferView"].get<std::size_t>()];
      const std::uint64_t component =
          element_bytes(accessor["componentType"].get<std::uint64_t>(), "SCALAR");
      const std::uint64_t step = std::max(count_of(view, "byteStride", at, 0), component);
      const std::uint64_t count = accessor["count"].get<std::uint64_t>();
      const std::string_view bytes = buffers(view["buffer"].get<std::size_t>());
      // check_accessors proved the span lies inside the view and the view inside the buffer.
      std::size_t offset =
          count_of(view, "byteOffset", at, 0) + count_of(accessor, "byteOffset", at, 0);
      for (std::uint64_t i = 0; i < count; ++i, offset += step) {
        const std::uint64_t index = component == 1   ? std::uint8_t(bytes[offset])
                                    : component == 2 ? le16(bytes, offset)
                                                     : le32(bytes, offset);
        if (index >= vertices) {
          refuse(at + "'s index " + std::to_string(i) + " is " + std::to_string(index) +
                 ", but the primitive has " + std::to_string(vertices) +
                 " vertices; the file is damaged");
        }
      }
    }
  }
}

// Instancing multiplies: a scene may list one root many times, a mesh may repeat one
// primitive, and Assimp builds a mesh per primitive and a node per use before anything is
// flattened. So what the scene amounts to is bounded from the counts first. check_nodes has
// proved the nodes a forest.
void check_instancing(const json& root) {
  const json& accessors = array_at(root, "accessors");
  const json& meshes = array_at(root, "meshes");
  const json& nodes = array_at(root, "nodes");
  std::uint64_t primitives = 0;
  std::vector<std::uint64_t> mesh_vertices(meshes.size(), 0);
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    for (const json& primitive : array_at(meshes[m], "primitives")) {
      ++primitives;
      mesh_vertices[m] += accessors[primitive["attributes"]["POSITION"].get<std::size_t>()]["count"]
                              .get<std::uint64_t>();
    }
  }
  if (primitives > kMaxPrimitives) {
    refuse("it has " + std::to_string(primitives) + " mesh primitives, over the limit of " +
           std::to_string(kMaxPrimitives) + "; merge primitives that share a material");
  }
  // Subtree totals, children before parents: a breadth-first order from the roots, reversed.
  std::vector<std::size_t> order;
  std::vector<bool> is_child(nodes.size(), false);
  for (const json& node : nodes)
    for (const json& c : array_at(node, "children")) is_child[c.get<std::size_t>()] = true;
  for (std::size_t n = 0; n < nodes.size(); ++n)
    if (!is_child[n]) order.push_back(n);
  for (std::size_t i = 0; i < order.size(); ++i)
    for (const json& c : array_at(nodes[order[i]], "children"))
      order.push_back(c.get<std::size_t>());
  std::vector<std::uint64_t> vertices(nodes.size(), 0), count(nodes.size(), 1);
  for (std::size_t i = order.size(); i-- > 0;) {
    const std::size_t n = order[i];
    if (nodes[n].contains("mesh"))
      vertices[n] += mesh_vertices[nodes[n]["mesh"].get<std::size_t>()];
    for (const json& c : array_at(nodes[n], "children")) {
      vertices[n] += vertices[c.get<std::size_t>()];
      count[n] += count[c.get<std::size_t>()];
    }
  }
  const json& scenes = array_at(root, "scenes");
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const std::string where = "scene " + std::to_string(s);
    if (!scenes[s].is_object()) refuse(where + " is not an object; the file is damaged");
    std::uint64_t scene_vertices = 0, scene_nodes = 0;
    for (const json& r : array_at(scenes[s], "nodes")) {
      if (!r.is_number_unsigned() || r.get<std::uint64_t>() >= nodes.size())
        refuse(where + " names a root that is no node; the file is damaged");
      // Each term is below 2^40 (counts fit their bytes) and there are fewer terms than
      // bytes in the file, so the sums cannot wrap.
      scene_vertices += vertices[r.get<std::size_t>()];
      scene_nodes += count[r.get<std::size_t>()];
    }
    if (scene_vertices > kMaxSceneVertices || scene_nodes > kMaxSceneNodes) {
      refuse(where + " places " + std::to_string(scene_vertices) + " vertices in " +
             std::to_string(scene_nodes) + " nodes once every node and root is instanced, over " +
             "the limits of " + std::to_string(kMaxSceneVertices) + " and " +
             std::to_string(kMaxSceneNodes) +
             " (a mesh used by many nodes is copied for each); simplify the scene");
    }
  }
}

void check_gltf_json(std::string_view text, const fs::path& folder,
                     std::optional<std::string_view> glb_bin, ReferencedFiles& referenced) {
  check_json_depth(text);
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    refuse(std::string("its JSON does not parse (") + e.what() + "); the file is damaged");
  }
  if (!root.is_object()) refuse("its JSON is not an object; this is not a glTF file");
  const auto asset = root.find("asset");
  const json* version = asset != root.end() && asset->is_object() && asset->contains("version")
                            ? &(*asset)["version"]
                            : nullptr;
  if (version == nullptr || !version->is_string() ||
      version->get<std::string>().rfind("2.", 0) != 0) {
    refuse("it is not glTF 2.0 (asset.version is " + (version ? version->dump() : "missing") +
           "); convert it to glTF 2.0");
  }
  for (const json& e : array_at(root, "extensionsRequired")) {
    if (e == "KHR_draco_mesh_compression" || e == "EXT_meshopt_compression") {
      refuse("it requires " + e.get<std::string>() +
             ", which is not supported; export "
             "without mesh compression");
    }
  }
  // Unsupported content first: its message helps more than any damage found after it.
  if (!array_at(root, "skins").empty()) {
    refuse(
        "it has skins (bones), which are not supported; export the mesh in its bind pose "
        "without the armature");
  }
  const std::vector<BufferSource> buffers = check_buffers(root, folder, glb_bin, referenced);
  check_accessors(root, check_buffer_views(root, buffers));
  check_meshes(root);
  check_nodes(root);
  check_instancing(root);
  BufferBytes bytes(buffers, glb_bin.value_or(std::string_view()));
  check_index_values(root, bytes);
  const json& images = array_at(root, "images");
  for (std::size_t i = 0; i < images.size(); ++i) {
    if (images[i].is_object() && images[i].contains("uri") && images[i]["uri"].is_string()) {
      uri_bytes(images[i]["uri"].get<std::string>(), folder, "image " + std::to_string(i), false);
    }
  }
}

// --- GLB ------------------------------------------------------------------------------------

constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kChunkJson = 0x4E4F534A;
constexpr std::uint32_t kChunkBin = 0x004E4942;

void check_glb_bytes(std::string_view b, const fs::path& folder, ReferencedFiles& referenced) {
  if (b.size() < 20 || le32(b, 0) != kGlbMagic) {
    refuse("it does not start with the binary glTF header ('glTF'); it is not a .glb file");
  }
  if (le32(b, 4) != 2) {
    refuse("it is binary glTF version " + std::to_string(le32(b, 4)) + "; only 2 is supported");
  }
  if (le32(b, 8) != b.size()) {
    refuse("its header says " + std::to_string(le32(b, 8)) + " bytes, but the file has " +
           std::to_string(b.size()) + "; it is truncated or damaged, re-export it");
  }
  std::optional<std::string_view> json_chunk;
  std::optional<std::string_view> bin;
  for (std::size_t at = 12; at < b.size();) {
    if (b.size() - at < 8) refuse("it ends inside a chunk header; it is truncated");
    const std::uint64_t length = le32(b, at);
    const std::uint32_t type = le32(b, at + 4);
    if (length > b.size() - at - 8) {
      refuse("the chunk at byte " + std::to_string(at) + " claims " + std::to_string(length) +
             " bytes, past the end of the file; it is truncated or damaged");
    }
    if (at == 12 && type != kChunkJson) refuse("its first chunk is not JSON; it is damaged");
    if (at == 12) json_chunk = b.substr(at + 8, length);
    if (at > 12 && type == kChunkBin && !bin) bin = b.substr(at + 8, length);
    at += 8 + length;
  }
  check_gltf_json(*json_chunk, folder, bin, referenced);
}

}  // namespace

std::string check_gltf(const fs::path& path, std::uint64_t size, ReferencedFiles& referenced) {
  return guarded(
      size, [&] { check_gltf_json(read_all(path), path.parent_path(), std::nullopt, referenced); });
}

std::string check_glb(const fs::path& path, std::uint64_t size, ReferencedFiles& referenced) {
  return guarded(size, [&] { check_glb_bytes(read_all(path), path.parent_path(), referenced); });
}

}  // namespace meshes::detail
