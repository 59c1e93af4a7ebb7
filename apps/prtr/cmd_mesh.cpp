// prtr mesh FILE: load a mesh the way every later stage will, and print what was found;
// with -o, write it (after --subdivide N rounds of Loop subdivision) as binary PLY.
#include "commands.h"
#include "flag_checks.h"
#include "mesh_flags.h"

#include "meshes/load.h"
#include "meshes/subdivide.h"
#include "meshes/write_ply.h"

#include <cstdio>
#include <filesystem>
#include <string>

namespace prtr_app {

// Named rather than anonymous: a unity build compiles every command in one unit.
namespace cmd_mesh {

// What the file held, what loading cleaned up, and the result every later stage sees.
void print_report(const meshes::LoadReport& report, const meshes::Mesh& mesh) {
  const meshes::Bounds b = meshes::bounds(mesh);
  double area = 0.0;
  for (const meshes::Triangle& t : mesh.triangles) area += 0.5 * meshes::double_area(mesh, t);

  std::printf("mesh        %s (%s)\n", report.path.c_str(), report.format.c_str());
  std::printf("file        %zu vertices, %zu faces (%zu polygons triangulated)\n",
              report.file_vertices, report.file_faces, report.polygons_triangulated);
  std::printf(
      "clean-up    %zu vertices welded, %zu unreferenced dropped, %zu degenerate "
      "faces dropped\n",
      report.vertices_welded, report.unreferenced_vertices_dropped,
      report.degenerate_faces_dropped);
  if (report.normals_from_file) {
    std::printf("normals     from the file (%zu vertices added for vertices with several)\n",
                report.vertices_split_by_file_normals);
  } else {
    std::printf("normals     computed: %zu vertices split at creases\n",
                report.vertices_split_at_creases);
  }
  std::printf("result      %zu vertices, %zu triangles\n", mesh.vertex_count(),
              mesh.triangle_count());
  std::printf("bounds      min (%.6g, %.6g, %.6g)  max (%.6g, %.6g, %.6g)\n", b.min.x(), b.min.y(),
              b.min.z(), b.max.x(), b.max.y(), b.max.z());
  std::printf("diagonal    %.6g\n", b.diagonal());
  std::printf("area        %.6g\n", area);
  std::printf("hash        %016llx\n", static_cast<unsigned long long>(meshes::content_hash(mesh)));
}

}  // namespace cmd_mesh

Runner add_mesh_command(CLI::App& app) {
  using namespace cmd_mesh;
  struct Options {
    std::string path;
    double weld = meshes::LoadOptions{}.weld_tolerance;
    std::string normals = "angle";
    MeshFlags mesh_flags;
    int subdivide = 0;
    std::string output;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Load a mesh and print its facts; optionally subdivide and write it");
  cmd->add_option("MESH", opt->path, std::string("Mesh file: ") + meshes::kMeshFormats)->required();
  add_checked_option(cmd, "--weld-tolerance", opt->weld,
                     "Weld positions closer than this fraction of the bounding-box diagonal "
                     "(negative: no welding)",
                     number_in(-1, 1));
  add_checked_option(cmd, "--normals", opt->normals, "Vertex normal weighting",
                     CLI::IsMember({"angle", "area"}));
  add_mesh_flags(cmd, opt->mesh_flags);
  cmd->add_option("--subdivide", opt->subdivide,
                  "Rounds of Loop subdivision before writing -o (each: ~4x the vertices)")
      ->check(integer_in(0, 6));
  cmd->add_option("-o,--output", opt->output, "Write the loaded (and subdivided) mesh here (.ply)");

  return [opt] {
    check_outputs({{"-o", opt->output}}, {{"MESH", opt->path}});
    if (opt->subdivide > 0 && opt->output.empty()) {
      throw UsageError("--subdivide needs -o OUT.ply to write the refined mesh to");
    }
    if (!opt->output.empty() && std::filesystem::path(opt->output).extension() != ".ply") {
      throw UsageError("-o " + opt->output + ": the refined mesh is written as PLY; name it .ply");
    }
    meshes::LoadOptions options = load_options(opt->mesh_flags);
    options.weld_tolerance = opt->weld;
    options.normal_weighting =
        opt->normals == "area" ? meshes::NormalWeighting::kArea : meshes::NormalWeighting::kAngle;
    meshes::LoadReport report;
    const meshes::Mesh mesh = meshes::load_mesh(opt->path, options, &report);
    print_report(report, mesh);
    if (opt->output.empty()) return;
    const meshes::Mesh refined = meshes::loop_subdivide(mesh, opt->subdivide);
    meshes::write_ply(opt->output, refined);
    std::printf("wrote       %s: %d round(s) of Loop subdivision, %zu vertices, %zu triangles\n",
                opt->output.c_str(), opt->subdivide, refined.vertex_count(),
                refined.triangle_count());
  };
}

}  // namespace prtr_app
