#include "prt/transfer.h"

#include "common/enum_names.h"

namespace prt {
namespace {
constexpr common::EnumName<TransferKind> kKindNames[] = {{TransferKind::kDiffuse, "diffuse"},
                                                         {TransferKind::kGlossy, "glossy"}};
}  // namespace

const char* transfer_kind_name(TransferKind kind) {
  return common::enum_name<TransferKind>(kKindNames, kind);
}

}  // namespace prt
