// Reading and writing ordinary image files (PNG, TIFF, EXR, ...) through OpenImageIO, with the
// project's error convention: any failure is an InputError naming the file. The spectral EXR
// layout has its own reader/writer (spectral_exr.h); this is for everything else.
#pragma once
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

// Writes interleaved pixels of `spec.format` with `spec.nchannels` per pixel (the format follows
// the file's extension). `spec` carries any metadata attributes.
void write_image_file(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* pixels);
// The bytes write_image_file would write to `file` (format from its extension), in memory.
std::string encode_image_file(const std::filesystem::path& file, const OIIO::ImageSpec& spec, const void* pixels);

// A whole image as interleaved floats.
struct FloatImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;
};
// Checks the size an image header claims (width x height x channels x bytes_per_value) against
// the memory limit before any pixel is allocated; InputError naming the file otherwise.
void check_image_spec(const std::filesystem::path& file, const OIIO::ImageSpec& spec, size_t bytes_per_value);
// What OpenImageIO said about a failed read, as one line: its lines joined by "; ", with the lines a
// library under it printed itself (captured by a LibraryStderr, renderer/core/process/library_stderr.h)
// when OIIO did not repeat them. Readers run OIIO inside a LibraryStderr({"libpng "}) so that
// libpng's own "libpng error: ..." never precedes the one line the user gets.
std::string library_error(std::string oiio_error, const std::vector<std::string>& library_lines);
// Reads the first subimage; a missing or unreadable file is an InputError naming it.
FloatImage read_image_file(const std::filesystem::path& file);

}  // namespace ofl
