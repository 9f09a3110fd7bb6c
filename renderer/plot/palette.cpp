#include "renderer/plot/palette.h"

namespace ofl {

Rgba palette_color(int i) {
  static const unsigned kColors[] = {0x1f77b4, 0xd62728, 0x2ca02c, 0xff7f0e, 0x9467bd,
                                     0x8c564b, 0xe377c2, 0x17becf, 0x7f7f7f, 0xbcbd22};
  return rgb_hex(kColors[((i % 10) + 10) % 10]);
}

}  // namespace ofl
