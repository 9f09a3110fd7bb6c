// Spectral OpenEXR files in the layout of Fichet, Pacanowski and Wilkie, "An OpenEXR Layout for
// Spectral Images", JCGT 10(3), 2021: one FLOAT channel per band named "S0.<nm>nm" with the decimal
// point written as a comma ("S0.550,000000nm"), header attributes spectralLayoutVersion = "1.0"
// and emissiveUnits = "W.m^-2.sr^-1", plus R, G, B channels (linear sRGB) for ordinary viewers.
// oralfluor adds an optional layer "fluorescence" (the fluorescent part of the radiance, channels
// fluorescence.S0.<nm>) and single-channel per-pixel planes "aov.*" (material, irradiance, ...).
#pragma once
#include <filesystem>
#include <string>

#include "renderer/image/spectral_image.h"

namespace ofl {

// Channel name for a band centre, e.g. 550 -> "S0.550,000000nm".
std::string spectral_channel_name(double nm);
// Parses "S0.550,000000nm" (comma or point) into 550; false when the name is not an S0 channel.
bool parse_spectral_channel_name(const std::string& name, double* nm);

// OpenEXR compresses and decompresses the chunks of a file on this many threads (0: on the caller's
// alone, OpenEXR's default). The bytes written are the same for any count.
void set_exr_threads(int threads);

void write_spectral_exr(const std::filesystem::path& file, const SpectralImage& img);
// The bytes write_spectral_exr would write (the same channels, layers, planes and attributes), for
// callers that store them themselves (the sweep's render cache writes them atomically).
std::string spectral_exr_bytes(const SpectralImage& img);
// Reads every S0 channel (any order, sorted by wavelength); throws InputError when the file is
// missing, unreadable or has no spectral channels.
SpectralImage read_spectral_exr(const std::filesystem::path& file);

// Linear sRGB of each pixel from its spectrum (CIE 1931 through the band means), scaled so that
// Y = 1 for a radiance of `white_radiance` at every band.
std::vector<float> spectral_to_linear_srgb(const SpectralImage& img, double white_radiance = 1.0);

}  // namespace ofl
