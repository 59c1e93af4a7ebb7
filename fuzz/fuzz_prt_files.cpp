// libFuzzer target for prtr's own binary files. Built four times: PRTR_FUZZ_PRTC picks the
// .prtc reader over the .prtx one, and PRTR_FUZZ_RESEAL recomputes the checksums of each
// mutated input first, so that mutations reach the checks behind the checksums instead of
// all failing at the first one.
#include "fuzz_support.h"

#include <cstdint>
#include <exception>
#include <vector>

#if PRTR_FUZZ_PRTC
#include "cpca/compressed_file.h"
#else
#include "prt/transfer_file.h"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
#if PRTR_FUZZ_PRTC
  const char* extension = ".prtc";
#if PRTR_FUZZ_RESEAL
  fuzz_support::reseal_compressed(bytes.data(), bytes.size());
#endif
#else
  const char* extension = ".prtx";
#if PRTR_FUZZ_RESEAL
  fuzz_support::reseal_transfer(bytes.data(), bytes.size());
#endif
#endif
  const auto& path = fuzz_support::write_input(bytes.data(), bytes.size(), extension);
  // Rejection by exception is the expected outcome for most inputs; crashes, leaks, hangs and
  // oversized allocations are what libFuzzer reports.
  try {
#if PRTR_FUZZ_PRTC
    cpca::read_compressed(path);
#else
    prt::read_transfer(path);
#endif
  } catch (const std::exception&) {
  }
  return 0;
}
