// Layered tissue presets (assets/tissues/layered) land in the measured brightness ranges the surface
// presets were calibrated to (docs/oral-scenes.md): fluorescence above 480 nm under a 405 nm LED
// as a fraction of a white target, tongue 3.3e-4..6.0e-4 and lip / buccal mucosa 2.2e-4..2.7e-4
// (oe_tongue_lip). The lesion presets change physiology, and the direction of each change is
// checked: dysplasia (less stromal collagen, more blood) and a blood spot return less fluorescence
// than the healthy tissue they derive from.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>

#include "tests/tissue_ratio.h"

using namespace ofl;

namespace {
// Through the table (the default transport), filled with half the default walks to keep the test
// short; its noise at this count is a few percent, well inside the ranges checked.
nlohmann::json preset(const std::string& name) {
  return {{"type", "layered_tissue"}, {"preset", name}, {"table_photons", 1000}};
}

const std::map<std::string, double>& ratios() {
  static const std::map<std::string, double> r = [] {
    std::map<std::string, double> m;
    for (const char* p : {"lateral_tongue", "dorsal_tongue", "dorsal_tongue_coated", "buccal_mucosa", "dysplasia",
                          "leukoplakia", "blood_spot"}) {
      auto v = test::fluorescence_ratios(preset(p), 405, 32, {{480, 700}, {625, 645}});
      m[p] = v[0];
      m[std::string(p) + "/red"] = v[1];
      std::printf("layered preset %-22s fluorescence / white target %.3g (625-645 nm: %.3g)\n", p, m[p],
                  m[std::string(p) + "/red"]);
    }
    return m;
  }();
  return r;
}
}  // namespace

TEST(LayeredPresets, HealthyTissueInMeasuredRanges) {
  const auto& r = ratios();
  for (const char* p : {"lateral_tongue", "dorsal_tongue"}) {
    EXPECT_GT(r.at(p), 3.3e-4) << p;
    EXPECT_LT(r.at(p), 6.0e-4) << p;
  }
  EXPECT_GT(r.at("buccal_mucosa"), 2.0e-4);
  EXPECT_LT(r.at("buccal_mucosa"), 3.0e-4);
}

TEST(LayeredPresets, LesionsChangeFluorescenceTheWayTheirPhysiologyDoes) {
  const auto& r = ratios();
  // Loss of stromal collagen fluorescence under a thicker, more absorbing epithelium.
  EXPECT_LT(r.at("dysplasia"), 0.8 * r.at("lateral_tongue"));
  // Blood absorbs the excitation and the emission before they reach the stroma or leave.
  EXPECT_LT(r.at("blood_spot"), 0.8 * r.at("lateral_tongue"));
  // Porphyrin in the coating adds a red band near 635 nm (oe_tongue_lip tongue spectra) while the
  // biofilm shades the tissue below: the total stays in the tongue range, the band stands out.
  EXPECT_GT(r.at("dorsal_tongue_coated"), 3.3e-4);
  EXPECT_LT(r.at("dorsal_tongue_coated"), 6.0e-4);
  EXPECT_GT(r.at("dorsal_tongue_coated/red"), 1.5 * r.at("dorsal_tongue/red"));
}
