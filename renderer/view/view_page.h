// `oralfluor view`: one self-contained HTML page for one or two images (view_image.h). Everything
// is inside the page (data as base64 in inert script elements, the viewer's script and style), so it
// works from a file:// URL with no network. The page shows an sRGB preview, the fluorescence-only
// view, any band, the material overlay; hovering or clicking a pixel plots its spectrum (radiance
// and fluorescence, with units), dragging a rectangle gives the region's mean spectrum, standard
// deviation and (r, g) chromaticity; two images sit side by side with one cursor. docs/view.md.
//
// Size: the spectra are stored as float16 of value / (channel maximum) (relative error <= 2^-11 of
// the value above 6e-5 of the channel's maximum), on a grid decimated by an integer factor k (k x k
// block means) so that each cube holds at most `max_values` numbers; the page says when k > 1.
// Previews are 8-bit sRGB at full size up to 4 Mpixel.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "renderer/view/view_image.h"

namespace ofl {

struct ViewOptions {
  int64_t max_values = 8'000'000;  // per cube (radiance, fluorescence): decimate above this
  std::string title;               // default: the file names
};

// The decimation factor the page uses for an image of w x h x channels values.
int view_decimation(int width, int height, int channels, int64_t max_values);

std::string view_page_html(const std::vector<ViewImage>& images, const ViewOptions& options);

// IEEE 754 binary16 of a float (round to nearest even; overflow to infinity), for the page's data.
uint16_t float_to_half(float f);
float half_to_float(uint16_t h);

}  // namespace ofl
