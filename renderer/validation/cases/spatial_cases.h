// Validation cases of the spatial transport of layered tissue (renderer/validation/cases/spatial_cases.cpp,
// docs/layered-tissue.md "Lateral transport"), run by `oralfluor bench <case>` and the tests.
#pragma once
#include <cstdint>
#include <string>

#include "renderer/validation/harness/bench_check.h"

namespace ofl {

CheckCaseResult spatial_fluorescence_pencil(long long samples, uint64_t seed);
// A disc of preset `inside` (radius a_mm) in lateral_tongue, smooth wet film, lit uniformly (10 degrees
// off the normal): the rendered profile of reflectance (broadband light) or fluorescence (405 nm) per
// ring around the disc's centre, over healthy tissue's, against the forward Monte Carlo of the same
// geometry (within 2 % or 3 combined standard errors); the position-free render's profile beside.
// `transport`: "spatial" (the profiles) or "volume" (the walk in the volume under the surface).
CheckCaseResult spatial_lesion_disc(const std::string& inside, double a_mm, bool fluorescence, long long samples, uint64_t seed,
                                    const std::string& transport = "spatial");

}  // namespace ofl
