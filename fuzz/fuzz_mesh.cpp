// libFuzzer target for meshes::load_mesh, built once per format: PRTR_FUZZ_EXTENSION (".obj",
// ".ply", ...) picks the reader, as the file name does for prtr.
#include "fuzz_support.h"
#include "meshes/load.h"

#include <OpenMesh/Core/System/omstream.hh>

#include <cstdint>
#include <exception>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // OpenMesh's readers report every odd line on stderr, which would bury libFuzzer's own
  // output and slow each run down.
  omerr().disable();
  omlog().disable();
  omout().disable();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return fuzz_support::load_file_input(data, size, PRTR_FUZZ_EXTENSION,
                                       [](const auto& path) { meshes::load_mesh(path); });
}
