// The one qualitative palette of every plot (charts, chromaticity plots, sweep reports): ten
// distinguishable colours, cycled.
#pragma once
#include "renderer/plot/vector_plot.h"

namespace ofl {

// The i-th colour (i taken modulo 10, negative i too): blue, red, green, orange, purple, brown,
// pink, cyan, grey, olive.
Rgba palette_color(int i);

}  // namespace ofl
