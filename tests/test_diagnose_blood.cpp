// Diagnose / item 6 interface: the blood absorber (Prahl hemoglobin, Beer-Lambert) that turns an
// accepted blood_absorption cause into material parameters.
#include <gtest/gtest.h>

#include <cmath>

#include "materials/corrections/diagnosis_corrections.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "renderer/spectral/chromophores/hemoglobin.h"

using namespace ofl;

TEST(DiagnoseBlood, OpticalDensityFollowsPrahlTable) {
  // Prahl: oxy-Hb 577 nm 55540 cm^-1/M (file row 576: 55540? we read the table itself), so
  // OD = eps * c * L with c L in umol/L*cm times 1e-6.
  const auto& t = hemoglobin_tables();
  BloodAbsorber b;
  b.oxy_uM_cm = 10;
  b.deoxy_uM_cm = 2;
  for (double nm : {414.0, 542.0, 560.0, 577.0, 650.0})
    EXPECT_NEAR(blood_optical_density(b, nm), 1e-6 * (10 * t.oxy.eval(nm) + 2 * t.deoxy.eval(nm)), 1e-12);
  // The Q bands of oxy-hemoglobin: 542 and 577 nm absorb more than the 560 nm valley between them.
  BloodAbsorber oxy;
  oxy.oxy_uM_cm = 5;
  EXPECT_GT(blood_optical_density(oxy, 577), 1.1 * blood_optical_density(oxy, 560));
  EXPECT_GT(blood_optical_density(oxy, 542), 1.1 * blood_optical_density(oxy, 560));
  // Soret band: more than 5x the Q bands.
  EXPECT_GT(blood_optical_density(oxy, 414), 5 * blood_optical_density(oxy, 577));
  EXPECT_NEAR(blood_transmittance(b, 577.0), std::pow(10.0, -blood_optical_density(b, 577)), 1e-12);
}

TEST(DiagnoseBlood, WholeBloodConversion) {
  // 150 g/L over 64500 g/mol = 2325.6 umol/L; 10 um = 1e-3 cm -> 2.3256 umol/L*cm in total.
  BloodAbsorber b = BloodAbsorber::whole_blood(10, 0.8);
  EXPECT_NEAR(b.total_uM_cm(), 150.0 / 64500.0 * 1e6 * 1e-3, 1e-9);
  EXPECT_NEAR(b.saturation(), 0.8, 1e-12);
}

TEST(DiagnoseBlood, EemUnderBloodKeepsStokesAndScalesByTransmittance) {
  WavelengthGrid g{350, 750, 5};
  GridEem fad = load_fluorophore("FAD", g);
  BloodAbsorber b;
  b.oxy_uM_cm = 8;
  b.excitation_path_factor = 1;
  GridEem out = apply_blood_to_eem(fad, b);
  auto t = blood_transmittance(b, g);
  int em = g.index_of(540), ex = g.index_of(450);
  EXPECT_NEAR(out.at(em, ex), fad.at(em, ex) * t[em] * t[ex], 1e-15);
  for (int e = 0; e < g.size(); ++e)
    for (int x = e; x < g.size(); ++x) EXPECT_EQ(out.at(e, x), 0.0);
  std::vector<double> refl(g.size(), 0.5);
  auto r = apply_blood_to_reflectance(refl, g, b);
  EXPECT_NEAR(r[em], 0.5 * t[em] * t[em], 1e-15);
}

TEST(DiagnoseBlood, MaterialCorrectionsFromAReport) {
  // The JSON that `oralfluor diagnose --json` prints, reduced to what the converter reads.
  nlohmann::json report = {
      {"causes",
       {{{"name", "blood_absorption"}, {"parameters", {{"oxy_uM_cm", 6.0}, {"deoxy_uM_cm", 1.5}}}, {"uncertainty", {{"oxy_uM_cm", 0.5}, {"deoxy_uM_cm", 0.4}}}},
        {{"name", "extra_fluorophore"}, {"parameters", {{"fluorophore", "chlorophyll_a"}, {"mean_fraction", 0.04}}}, {"uncertainty", {{"mean_fraction", 0.01}}}},
        {{"name", "emission_broadening"}, {"parameters", {{"fwhm_nm", 12.0}}}, {"uncertainty", {{"fwhm_nm", 1.0}}}}}},
      {"model_options", {{"blood_excitation_path_factor", 1.0}}}};
  TissueCorrections c = tissue_corrections_from_report(report);
  ASSERT_TRUE(c.blood.has_value());
  EXPECT_DOUBLE_EQ(c.blood->oxy_uM_cm, 6.0);
  EXPECT_DOUBLE_EQ(c.blood->deoxy_uM_cm, 1.5);
  EXPECT_DOUBLE_EQ(c.blood->excitation_path_factor, 1.0);
  ASSERT_EQ(c.extra_fluorophores.size(), 1u);
  EXPECT_EQ(c.extra_fluorophores[0].name, "chlorophyll_a");
  EXPECT_DOUBLE_EQ(c.emission_broadening_fwhm_nm, 12.0);
  // The blood optical-density spectrum on a grid is what a tissue material would store.
  WavelengthGrid g{400, 700, 10};
  auto od = blood_optical_density_on_grid(*c.blood, g);
  EXPECT_NEAR(od[g.index_of(580)], blood_optical_density(*c.blood, 580.0), 0.05 * od[g.index_of(580)]);
  EXPECT_TRUE(tissue_corrections_from_report(nlohmann::json{{"causes", nlohmann::json::array()}}).empty());
}
