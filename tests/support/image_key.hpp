// Tests run programs in one thread (virtual time, or before and after a
// real-time run): they may touch the images (runtime/core/image_access.hpp).
#pragma once

#include "runtime/core/image_access.hpp"

namespace syncplc::testing {

class ImageKey {
 public:
  static ImageAccess get() { return ImageAccess{}; }
};
inline ImageAccess image_key() { return ImageKey::get(); }

}  // namespace syncplc::testing
