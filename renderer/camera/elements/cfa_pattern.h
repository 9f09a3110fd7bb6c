// Bayer colour filter array (CFA) layouts. A pattern is named by the colours of its 2x2 cell read
// row by row from the top-left pixel (0, 0) of the image, the convention of TIFF/EP and DNG
// (CFAPattern tag) and of most sensor datasheets: "RGGB" puts red at (0,0), green at (1,0) and
// (0,1), blue at (1,1). x grows to the right, y downwards.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace ofl {

enum class CfaPattern { kRGGB, kGRBG, kGBRG, kBGGR };

// Channel indices used everywhere in the camera module (and in DNG's CFAPattern bytes).
enum CfaChannel : int { kRed = 0, kGreen = 1, kBlue = 2 };
constexpr int kCfaChannels = 3;

// Channel indices of the 2x2 cell in row-major order: cell[(y % 2) * 2 + (x % 2)].
std::array<uint8_t, 4> cfa_cell(CfaPattern p);
// Channel (kRed, kGreen, kBlue) of the pixel at column x, row y.
inline int cfa_channel(CfaPattern p, int x, int y) { return cfa_cell(p)[(y & 1) * 2 + (x & 1)]; }

std::string cfa_name(CfaPattern p);
// "RGGB", "GRBG", "GBRG" or "BGGR" (upper or lower case); nullopt otherwise.
std::optional<CfaPattern> parse_cfa_name(const std::string& name);
// "R", "G", "B".
const char* channel_name(int channel);

}  // namespace ofl
