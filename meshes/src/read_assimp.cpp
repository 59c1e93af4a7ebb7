// meshes/read_assimp.cpp: Assimp behind the interface of read_assimp.h.
//
// No post-processing is requested except Assimp's validation of its own data structure
// (indices in range, counts consistent): triangulation, welding and computed normals are
// ours, so every format goes through the same clean-up. Normals the file itself stores
// (glTF NORMAL) are passed on when every mesh has them. Unsupported content is refused rather than
// read in a pose nobody asked for: bones (skinning) and anim meshes (morph targets).
#include "read_assimp.h"

#include "common/input_file.h"

#include <assimp/DefaultIOStream.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>

#include <Eigen/LU>

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace meshes::detail {

namespace {

namespace fs = std::filesystem;

// A stream over a file opened by common::open_input_file (the constructor that takes a
// FILE* is protected in Assimp).
class CheckedStream : public Assimp::DefaultIOStream {
 public:
  CheckedStream(std::FILE* file, const std::string& name) : Assimp::DefaultIOStream(file, name) {}
};

// The only files Assimp may open: the asset and the files its guard checked, by the names
// Assimp asks for (the folder joined with the URI as written). Anything else fails to open,
// so a URI the guard did not see, or a file swapped for a FIFO since, reaches nothing.
class CheckedFiles : public Assimp::IOSystem {
 public:
  CheckedFiles(const fs::path& asset, const ReferencedFiles& referenced) {
    allowed_.push_back({asset.lexically_normal(), asset});
    for (const ReferencedFile& r : referenced)
      allowed_.push_back({(asset.parent_path() / r.uri).lexically_normal(), r.checked});
  }

  bool Exists(const char* name) const override { return resolve(name) != nullptr; }
  char getOsSeparator() const override { return '/'; }

  Assimp::IOStream* Open(const char* name, const char* mode) override {
    const fs::path* path = resolve(name);
    if (path == nullptr || std::string_view(mode).find_first_of("wa+") != std::string_view::npos) {
      problem_ = std::string("it refers to '") + name + "', which was not checked";
      return nullptr;
    }
    common::InputFile in = common::open_input_file(*path, kMaxAssetBytes);
    if (in.file == nullptr) {
      problem_ = path->string() + " " + in.problem;
      return nullptr;
    }
    return new CheckedStream(in.release(), path->string());
  }

  void Close(Assimp::IOStream* stream) override { delete stream; }

  const std::string& problem() const { return problem_; }

 private:
  const fs::path* resolve(const char* name) const {
    const fs::path wanted = fs::path(name).lexically_normal();
    for (const auto& [as_asked, checked] : allowed_)
      if (as_asked == wanted) return &checked;
    return nullptr;
  }

  std::vector<std::pair<fs::path, fs::path>> allowed_;
  std::string problem_;
};

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return out;
}

// Why `mesh` cannot be loaded, or empty. Meshes of points or lines only are skipped by the
// caller; they are not errors unless nothing else is left.
std::string unsupported(const aiMesh& mesh, unsigned index) {
  const std::string which =
      "mesh " + std::to_string(index) +
      (mesh.mName.length > 0 ? " ('" + std::string(mesh.mName.C_Str()) + "')" : std::string());
  if (mesh.mNumBones > 0) {
    return which + " is skinned (" + std::to_string(mesh.mNumBones) +
           " bones), which is not supported; export it in its bind pose without the armature";
  }
  if (mesh.mNumAnimMeshes > 0) {
    return which +
           " has morph targets (anim meshes), which are not supported; apply them "
           "and export one pose";
  }
  return {};
}

bool has_polygons(const aiMesh& mesh) {
  return (mesh.mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON)) != 0;
}

// Appends `mesh` transformed by `world`; faces of fewer than three corners (points and lines
// in a mixed mesh) are left out.
// Normals go through the inverse transpose of the node transform (non-uniform scale) and are
// collected in `normals` while every mesh so far has them.
void append(const aiMesh& mesh, const Eigen::Matrix4d& world, RawPolygons& out, bool& normals) {
  const std::int64_t base = std::int64_t(out.positions.size());
  for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
    const aiVector3D& p = mesh.mVertices[v];
    const Eigen::Vector4d q = world * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
    out.positions.push_back((q.head<3>() / q.w()).cast<float>());
  }
  normals = normals && mesh.HasNormals();
  if (normals) {
    const Eigen::Matrix3d to_world = world.topLeftCorner<3, 3>().inverse().transpose();
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& n = mesh.mNormals[v];
      out.normals.push_back((to_world * Eigen::Vector3d(n.x, n.y, n.z)).cast<float>());
    }
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices < 3) continue;
    for (unsigned c = 0; c < face.mNumIndices; ++c) out.corners.push_back(base + face.mIndices[c]);
    out.face_offsets.push_back(out.corners.size());
  }
}

// Walks the node tree with an explicit stack (its depth is the file's to choose).
std::string flatten(const aiScene& scene, RawPolygons& out, bool normals) {
  std::vector<std::pair<const aiNode*, Eigen::Matrix4d>> stack;
  stack.emplace_back(scene.mRootNode, to_eigen(scene.mRootNode->mTransformation));
  std::uint64_t vertices = 0;
  bool any_polygons = false;
  while (!stack.empty()) {
    const auto [node, world] = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const unsigned index = node->mMeshes[i];
      const aiMesh& mesh = *scene.mMeshes[index];
      if (const std::string problem = unsupported(mesh, index); !problem.empty()) return problem;
      if (!has_polygons(mesh)) continue;
      any_polygons = true;
      vertices += mesh.mNumVertices;
      if (vertices > kMaxSceneVertices) {
        return "the flattened scene has over " + std::to_string(kMaxSceneVertices) +
               " vertices (meshes used by many nodes are copied per node); simplify it";
      }
      append(mesh, world, out, normals);
    }
    for (unsigned c = node->mNumChildren; c-- > 0;) {
      const aiNode* child = node->mChildren[c];
      stack.emplace_back(child, world * to_eigen(child->mTransformation));
    }
  }
  if (!normals) out.normals.clear();
  if (!any_polygons) {
    return "no node holds triangles or polygons (only points or lines, or no meshes); export "
           "the surface with its faces";
  }
  return {};
}

}  // namespace

std::string read_assimp(const fs::path& path, const ReferencedFiles& referenced, RawPolygons& out,
                        bool keep_normals) {
  Assimp::Importer importer;
  auto* files = new CheckedFiles(path, referenced);
  importer.SetIOHandler(files);  // the importer owns it from here
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    const std::string why = files->problem().empty() ? "" : ": " + files->problem();
    return std::string("Assimp could not read it (") + importer.GetErrorString() + why +
           "); fix or re-export the file";
  }
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr) {
    return "Assimp read an incomplete scene (no geometry, or only animation); export the "
           "meshes";
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    if (const std::string problem = unsupported(*scene->mMeshes[m], m); !problem.empty()) {
      return problem;
    }
  }
  return flatten(*scene, out, keep_normals);
}

}  // namespace meshes::detail
