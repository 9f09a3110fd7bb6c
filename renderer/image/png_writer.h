// 8-bit sRGB PNG previews through OpenImageIO.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace ofl {

// Writes linear RGB (3 floats per pixel) as sRGB PNG after multiplying by `exposure`.
void write_srgb_png(const std::filesystem::path& file, int width, int height, const std::vector<float>& linear_rgb,
                    double exposure);
// The same PNG as bytes in memory (a thumbnail embedded in a document).
std::string srgb_png_bytes(int width, int height, const std::vector<float>& linear_rgb, double exposure);
// An exposure that maps the given percentile of luminance to `target` (auto-exposure for previews).
double auto_exposure(const std::vector<float>& linear_rgb, double percentile = 0.99, double target = 0.9);

}  // namespace ofl
