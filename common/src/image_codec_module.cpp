// The prtr_oiio module's one exported symbol (common/image_codec.h): everything else in the
// module is hidden, so it cannot interpose on the executable's own names.
#include "oiio_codec.h"

extern "C" __attribute__((visibility("default"))) common::ImageCodecEntry prtr_image_codec_entry() {
  return {common::kImageCodecInterface, &common::oiio_image_codec()};
}
