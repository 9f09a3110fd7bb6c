#include "renderer/image/image_file.h"

#include <OpenImageIO/filesystem.h>

#include "renderer/core/atomic_file.h"
#include "renderer/core/error.h"
#include "renderer/core/memory_limit.h"
#include "renderer/image/exr_header.h"

namespace ofl {

void write_image_file(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* pixels) {
  // The writer is chosen by the final name's extension; the bytes are produced in memory and go to
  // disk through write_file_atomic, where every write is checked (OIIO's file writers do not all
  // notice a full disk).
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out) throw InputError(file.string(), "", "cannot create an image writer: " + OIIO::geterror());
  // OpenImageIO stamps TIFF and EXR files with the wall-clock DateTime unless one is given: an
  // empty one keeps identical runs byte-identical.
  OIIO::ImageSpec s = spec;
  if (!s.find_attribute("DateTime")) s.attribute("DateTime", "");
  if (out->supports("ioproxy")) {
    OIIO::Filesystem::IOVecOutput mem;
    OIIO::Filesystem::IOProxy* proxy = &mem;
    s.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    if (!out->open(file.string(), s) || !out->write_image(spec.format, pixels) || !out->close())
      throw InputError(file.string(), "", "cannot write image: " + out->geterror());
    const auto& b = mem.buffer();
    write_file_atomic(file, std::string(reinterpret_cast<const char*>(b.data()), b.size()));
    return;
  }
  write_via_temporary(file, [&](const std::filesystem::path& tmp) {
    if (!out->open(tmp.string(), s) || !out->write_image(spec.format, pixels) || !out->close())
      throw InputError(file.string(), "", "cannot write image: " + out->geterror());
  });
}

void check_image_spec(const std::filesystem::path& file, const OIIO::ImageSpec& spec, size_t bytes_per_value) {
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InputError(file.string(), "header", "image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                                  " pixels with " + std::to_string(spec.nchannels) + " channels");
  check_memory(file.string(), "header", double(spec.width) * double(spec.height) * double(spec.nchannels) * double(bytes_per_value),
               "an image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels with " +
                   std::to_string(spec.nchannels) + " channels");
}

FloatImage read_image_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "image file not found");
  check_exr_header(file);  // an EXR's attribute sizes, before OpenEXR trusts them
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError(file.string(), "", "cannot read image: " + printable(OIIO::geterror(), 200));
  const OIIO::ImageSpec& spec = in->spec();
  check_image_spec(file, spec, sizeof(float));
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
