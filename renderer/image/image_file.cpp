#include "renderer/image/image_file.h"

#include "renderer/core/error.h"

namespace ofl {

void write_image_file(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* pixels) {
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) throw InputError(file.string(), "", "cannot create an image writer: " + OIIO::geterror());
  if (!out->open(file.string(), spec) || !out->write_image(spec.format, pixels) || !out->close())
    throw InputError(file.string(), "", "cannot write image: " + out->geterror());
}

FloatImage read_image_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "image file not found");
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError(file.string(), "", "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  FloatImage im;
  im.width = spec.width;
  im.height = spec.height;
  im.channels = spec.nchannels;
  im.pixels.resize(static_cast<size_t>(im.width) * im.height * im.channels);
  if (!in->read_image(0, 0, 0, im.channels, OIIO::TypeDesc::FLOAT, im.pixels.data()))
    throw InputError(file.string(), "", "cannot read image pixels: " + in->geterror());
  return im;
}

}  // namespace ofl
