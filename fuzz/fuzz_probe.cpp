// libFuzzer target for probes::load_probe through OpenImageIO, built once per format
// (PRTR_FUZZ_EXTENSION ".hdr" or ".exr").
#include "fuzz_support.h"
#include "probes/load.h"

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <exception>

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One thread: libFuzzer's leak and RSS accounting, and reproducing a crash, are simpler
  // without OpenImageIO's and OpenEXR's worker pools.
  OIIO::attribute("threads", 1);
  OIIO::attribute("exr_threads", 1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return fuzz_support::load_file_input(data, size, PRTR_FUZZ_EXTENSION,
                                       [](const auto& path) { probes::load_probe(path); });
}
