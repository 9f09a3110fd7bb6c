#include "renderer/camera/elements/cfa_pattern.h"

#include <algorithm>
#include <cctype>

namespace ofl {

std::array<uint8_t, 4> cfa_cell(CfaPattern p) {
  switch (p) {
    case CfaPattern::kRGGB: return {kRed, kGreen, kGreen, kBlue};
    case CfaPattern::kGRBG: return {kGreen, kRed, kBlue, kGreen};
    case CfaPattern::kGBRG: return {kGreen, kBlue, kRed, kGreen};
    case CfaPattern::kBGGR: return {kBlue, kGreen, kGreen, kRed};
  }
  return {kRed, kGreen, kGreen, kBlue};
}

std::string cfa_name(CfaPattern p) {
  std::string s;
  for (uint8_t c : cfa_cell(p)) s += channel_name(c);
  return s;
}

std::optional<CfaPattern> parse_cfa_name(const std::string& name) {
  std::string u = name;
  std::transform(u.begin(), u.end(), u.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  for (CfaPattern p : {CfaPattern::kRGGB, CfaPattern::kGRBG, CfaPattern::kGBRG, CfaPattern::kBGGR})
    if (cfa_name(p) == u) return p;
  return std::nullopt;
}

const char* channel_name(int c) { return c == kRed ? "R" : c == kGreen ? "G" : "B"; }

}  // namespace ofl
