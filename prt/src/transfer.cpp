#include "prt/transfer.h"

namespace prt {

const char* transfer_kind_name(TransferKind kind) {
  switch (kind) {
    case TransferKind::kDiffuse:
      return "diffuse";
    case TransferKind::kGlossy:
      return "glossy";
  }
  return "unknown";  // only reachable through a cast of an out-of-range integer
}

}  // namespace prt
