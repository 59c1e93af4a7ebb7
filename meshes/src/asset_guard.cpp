// meshes/asset_guard.cpp: the checks in front of Assimp (see asset_guard.h).
//
// Every check reports by throwing Refusal inside this file; the entry points turn it into
// the returned string. Sizes are compared in 64 bits after bounding each factor, so no
// claimed count can overflow a comparison.
#include "asset_guard.h"

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

struct Refusal {
  std::string problem;
};

[[noreturn]] void refuse(const std::string& problem) {
  throw Refusal{problem};
}

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::uint32_t le32(std::string_view b, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) |
         (std::uint32_t(p[3]) << 24);
}

std::uint16_t le16(std::string_view b, std::size_t at) {
  const auto* p = reinterpret_cast<const unsigned char*>(b.data() + at);
  return std::uint16_t(p[0] | (p[1] << 8));
}

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

std::vector<std::uint64_t> check_buffers(const json& root, const fs::path& folder,
                                         std::optional<std::uint64_t> glb_bin) {
  std::vector<std::uint64_t> lengths;
  const json& buffers = array_at(root, "buffers");
  for (std::size_t b = 0; b < buffers.size(); ++b) {
    const std::string where = "buffer " + std::to_string(b);
    const json& buffer = buffers[b];
    if (!buffer.is_object()) refuse(where + " is not an object; the file is damaged");
    const std::uint64_t length = count_of(buffer, "byteLength", where);
    std::uint64_t available = 0;
    if (const auto uri = buffer.find("uri"); uri != buffer.end()) {
      if (!uri->is_string()) refuse(where + "'s uri is not a string; the file is damaged");
      available = uri_bytes(uri->get<std::string>(), folder, where);
    } else if (b == 0 && glb_bin) {
      available = *glb_bin;
    } else {
      refuse(where + " has no uri and is not the .glb's binary chunk; the file is damaged");
    }
    if (length > available) {
      refuse(where + " claims " + std::to_string(length) + " bytes, but its data holds " +
             std::to_string(available) + "; the file or its .bin is truncated");
    }
    lengths.push_back(length);
  }
  return lengths;
}

std::vector<std::uint64_t> check_buffer_views(const json& root,
                                              const std::vector<std::uint64_t>& buffers) {
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

void check_gltf_json(std::string_view text, const fs::path& folder,
                     std::optional<std::uint64_t> glb_bin) {
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
  const std::vector<std::uint64_t> buffers = check_buffers(root, folder, glb_bin);
  check_accessors(root, check_buffer_views(root, buffers));
  check_meshes(root);
  check_nodes(root);
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

void check_glb_bytes(std::string_view b, const fs::path& folder) {
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
  std::optional<std::uint64_t> bin;
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
    if (at > 12 && type == kChunkBin && !bin) bin = length;
    at += 8 + length;
  }
  check_gltf_json(*json_chunk, folder, bin);
}

// --- 3DS ------------------------------------------------------------------------------------

// Chunks whose body is a list of chunks (0x4000 after its name). Every chunk's claimed length
// is checked against its parent's end, iteratively, before Assimp's own walk.
// The keyframer (0xB000) holds node tags 0xB001..0xB007, which hold tracks.
bool is_3ds_container(std::uint16_t id) {
  return id == 0x4D4D || id == 0x3D3D || id == 0x4000 || id == 0x4100 || id == 0xAFFF ||
         (id >= 0xB000 && id <= 0xB007);
}

// Keyframe tracks (0xB020 position ... 0xB029 hide): a 10-byte header, a 32-bit key count,
// then keys of at least 6 bytes (frame and flags). Assimp reserves the count times 24 bytes
// before reading a key, so a 150-byte file could ask for 51 GB; the count must fit the chunk.
void check_3ds_track(std::string_view b, std::size_t at, std::uint64_t length) {
  constexpr std::uint64_t kHeader = 6 + 10 + 4;
  constexpr std::uint64_t kSmallestKey = 6;
  const std::uint64_t keys = length >= kHeader ? le32(b, at + 16) : 0;
  if (length < kHeader || keys > (length - kHeader) / kSmallestKey) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "%04x", le16(b, at));
    refuse("keyframe track 0x" + std::string(hex) + " at byte " + std::to_string(at) + " claims " +
           std::to_string(keys) + " keys in " + std::to_string(length) +
           " bytes; the file is damaged");
  }
}

// Vertex (0x4110, 12 bytes each), face (0x4120, 8) and texture coordinate (0x4140, 8) lists:
// a 16-bit count, then the records. Assimp would stop at the chunk's end with a message that
// names nothing; this one says which list is short.
void check_3ds_list(std::string_view b, std::size_t at, std::uint64_t length) {
  const std::uint16_t id = le16(b, at);
  const std::uint64_t record = id == 0x4110 ? 12 : 8;
  const std::uint64_t count = length >= 8 ? le16(b, at + 6) : 0;
  if (length < 8 || 8 + count * record > length) {
    const char* what = id == 0x4110 ? "vertex" : id == 0x4120 ? "face" : "texture coordinate";
    refuse(std::string(what) + " list chunk at byte " + std::to_string(at) + " claims " +
           std::to_string(count) + " records of " + std::to_string(record) + " bytes in " +
           std::to_string(length) + " bytes; the file is damaged");
  }
}

void check_3ds_bytes(std::string_view b) {
  if (b.size() < 6 || le16(b, 0) != 0x4D4D) {
    refuse("it does not start with a 3DS main chunk (0x4d4d); it is not a 3DS file");
  }
  if (le32(b, 2) < 6 || le32(b, 2) > b.size()) {
    refuse("chunk 0x4d4d at byte 0 claims " + std::to_string(le32(b, 2)) +
           " bytes, but the file has " + std::to_string(b.size()) + "; the file is damaged");
  }
  // The ends of the chunks enclosing `at`, innermost last.
  std::vector<std::size_t> open{le32(b, 2)};
  std::size_t at = 6;
  while (!open.empty()) {
    const std::size_t end = open.back();
    if (at >= end) {
      at = end;
      open.pop_back();
      continue;
    }
    if (end - at < 6)
      refuse("a chunk header at byte " + std::to_string(at) +
             " is cut off; "
             "the file is damaged");
    const std::uint16_t id = le16(b, at);
    const std::uint64_t length = le32(b, at + 2);
    if (length < 6 || length > end - at) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "%04x", id);
      refuse("chunk 0x" + std::string(hex) + " at byte " + std::to_string(at) + " claims " +
             std::to_string(length) + " bytes, past its parent's end; the file is damaged");
    }
    if (id >= 0xB020 && id <= 0xB029) check_3ds_track(b, at, length);
    if (id == 0x4110 || id == 0x4120 || id == 0x4140) check_3ds_list(b, at, length);
    if (!is_3ds_container(id)) {
      at += length;
      continue;
    }
    if (open.size() > std::size_t(kMax3dsDepth)) {
      refuse("its chunks nest deeper than " + std::to_string(kMax3dsDepth) +
             " levels; no 3DS file needs that, the file is damaged");
    }
    std::size_t body = at + 6;
    if (id == 0x4000) {  // a zero-terminated object name comes first
      while (body < at + length && b[body] != '\0') ++body;
      ++body;
    }
    open.push_back(std::size_t(at + length));
    at = body;
  }
}

template <class Check>
std::string guarded(std::uint64_t size, const Check& check) {
  if (size > kMaxAssetBytes) {
    return "the file has " + std::to_string(size) + " bytes, over the " +
           std::to_string(kMaxAssetBytes >> 20) + " MiB limit for glTF and 3DS assets";
  }
  try {
    check();
  } catch (const Refusal& r) {
    return r.problem;
  }
  return {};
}

}  // namespace

std::string check_gltf(const fs::path& path, std::uint64_t size) {
  return guarded(size, [&] { check_gltf_json(read_all(path), path.parent_path(), std::nullopt); });
}

std::string check_glb(const fs::path& path, std::uint64_t size) {
  return guarded(size, [&] { check_glb_bytes(read_all(path), path.parent_path()); });
}

std::string check_3ds(const fs::path& path, std::uint64_t size) {
  return guarded(size, [&] { check_3ds_bytes(read_all(path)); });
}

}  // namespace meshes::detail
