// libFuzzer target for the surface light field's files. Built four times: PRTR_FUZZ_SLFC picks
// the compressed .slfc reader over the baked .slf one, and PRTR_FUZZ_RESEAL recomputes the
// checksums first. Both formats keep the payload checksum at byte 104 over everything after
// the 128-byte header, as .prtx does, so the .prtx reseal serves them.
#include "fuzz_support.h"

#include <cstdint>
#include <exception>
#include <vector>

#if PRTR_FUZZ_SLFC
#include "pipeline/slf_file.h"
#else
#include "prt/slf_bake.h"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
#if PRTR_FUZZ_RESEAL
  fuzz_support::reseal_transfer(bytes.data(), bytes.size());
#endif
#if PRTR_FUZZ_SLFC
  const auto& path = fuzz_support::write_input(bytes.data(), bytes.size(), ".slfc");
#else
  const auto& path = fuzz_support::write_input(bytes.data(), bytes.size(), ".slf");
#endif
  // Rejection by exception is the expected outcome for most inputs; crashes, leaks, hangs and
  // oversized allocations are what libFuzzer reports.
  try {
#if PRTR_FUZZ_SLFC
    pipeline::read_slfc(path);
#else
    prt::read_slf(path);
#endif
  } catch (const std::exception&) {
  }
  return 0;
}
