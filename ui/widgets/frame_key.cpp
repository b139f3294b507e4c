#include "ui/widgets/frame_key.h"

namespace calibench::ui {

void FrameKey::Mix(const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) key_ = (key_ ^ p[i]) * 0x100000001b3ull;
}

}  // namespace calibench::ui
