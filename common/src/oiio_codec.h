// common/src/oiio_codec.h: the image codec on OpenImageIO. Compiled only into the prtr_oiio
// module, never into the common library, so that only that module links OpenImageIO
// (common/image_codec.h).
#pragma once

#include "common/image_codec.h"

namespace common {

const ImageCodec& oiio_image_codec();

}  // namespace common
