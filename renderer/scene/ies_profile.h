// The IES LM-63 reader behind an LED's {"ies_file": ...} profile (renderer/scene/led_light.cpp),
// declared on its own so the fuzz harnesses (tests/fuzz/) can enter it directly.
#pragma once
#include <filesystem>
#include <utility>
#include <vector>

namespace ofl {

// Relative intensity against polar angle (degrees, 0..90) from a TILT=NONE photometric file:
// candela averaged over the horizontal angles. Counts are bounded (at most 10000 angles each way)
// and checked as numbers before use; negative candela and zero on-axis candela are InputErrors
// naming the file.
std::vector<std::pair<double, double>> read_ies_profile(const std::filesystem::path& file);

}  // namespace ofl
