#include "renderer/image/image_file.h"

#include <OpenImageIO/filesystem.h>

#include <cstdio>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/library_stderr.h"
#include "renderer/core/process/memory_limit.h"
#include "renderer/image/exr_header.h"

namespace ofl {

std::string encode_image_file(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* pixels) {
  // The writer is chosen by the name's extension and produces its bytes in memory (OIIO's file
  // writers do not all notice a full disk); write_image_file sends them through write_file_atomic.
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
    return std::string(reinterpret_cast<const char*>(b.data()), b.size());
  }
  // A writer without an in-memory mode writes an in-memory file by name.
  return bytes_via_memory_file(file, [&](const std::filesystem::path& name) {
    if (!out->open(name.string(), s) || !out->write_image(spec.format, pixels) || !out->close())
      throw InputError(file.string(), "", "cannot write image: " + out->geterror());
  });
}

void write_image_file(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* pixels) {
  write_file_atomic(file, encode_image_file(file, spec, pixels));
}

void check_image_spec(const std::filesystem::path& file, const OIIO::ImageSpec& spec, size_t bytes_per_value) {
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InputError(file.string(), "header", "image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                                                  " pixels with " + std::to_string(spec.nchannels) + " channels");
  check_memory(file.string(), "header", double(spec.width) * double(spec.height) * double(spec.nchannels) * double(bytes_per_value),
               "an image of " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + " pixels with " +
                   std::to_string(spec.nchannels) + " channels");
}

std::string library_error(std::string oiio, const std::vector<std::string>& library) {
  for (size_t at; (at = oiio.find('\n')) != std::string::npos;) oiio.replace(at, 1, "; ");
  for (const auto& l : library)
    if (oiio.find(l.substr(l.find(':') == std::string::npos ? 0 : l.find(':') + 2)) == std::string::npos) oiio += "; " + l;
  return printable(oiio, 200);
}

FloatImage read_image_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "image file not found");
  check_exr_header(file);  // an EXR's attribute sizes, before OpenEXR trusts them
  // libpng prints "libpng error: ..." itself before OIIO reports the error: kept off stderr, so
  // the one line the user sees is ours (renderer/core/process/library_stderr.h).
  LibraryStderr quiet({"libpng "});
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) throw InputError(file.string(), "", "cannot read image: " + library_error(OIIO::geterror(), quiet.end()));
  const OIIO::ImageSpec& spec = in->spec();
  check_image_spec(file, spec, sizeof(float));
  FloatImage im;
  im.width = spec.width;
  im.height = spec.height;
  im.channels = spec.nchannels;
  im.pixels.resize(static_cast<size_t>(im.width) * im.height * im.channels);
  const bool ok = in->read_image(0, 0, 0, im.channels, OIIO::TypeDesc::FLOAT, im.pixels.data());
  std::vector<std::string> library = quiet.end();
  if (!ok) throw InputError(file.string(), "", "cannot read image pixels: " + library_error(in->geterror(), library));
  for (const auto& l : library) std::fprintf(stderr, "warning: %s: %s\n", file.string().c_str(), printable(l, 200).c_str());
  return im;
}

}  // namespace ofl
