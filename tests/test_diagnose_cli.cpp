// Diagnose CLI end to end on the shipped camera example (synthetic, hidden crosstalk): the JSON
// report has the keys scripts rely on, names the hidden cause with parameters and uncertainties,
// and -o writes the report, the residual table and the SVG plots.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "materials/corrections/diagnosis_corrections.h"

namespace fs = std::filesystem;

TEST(DiagnoseCli, CameraExampleJsonReportAndFiles) {
  fs::path out = fs::temp_directory_path() / ("ofl_diagnose_cli_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::string src = OFL_SOURCE_DIR;
  std::string cmd = std::string(OFL_BINARY) + " diagnose " + src + "/assets/measurements/camera_example --model " + src +
                    "/scenes/diagnose/camera_example.json --json -o " + out.string() + " > " + (out.string() + ".json");
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out.string() + ".json");
  nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_TRUE(j.contains("causes"));
  ASSERT_TRUE(j.contains("rmse_baseline_heldout"));
  ASSERT_TRUE(j.contains("rmse_extended_heldout"));
  EXPECT_LT(j["rmse_extended_heldout"].get<double>(), 0.2 * j["rmse_baseline_heldout"].get<double>());
  ASSERT_EQ(j["causes"].size(), 1u);
  auto& c = j["causes"][0];
  EXPECT_EQ(c["name"], "crosstalk");
  // Hidden: red gets 7.77 % of green, blue gets 7.04 % of red (assets/measurements/camera_example/README.md).
  EXPECT_NEAR(c["parameters"]["r_from_g"].get<double>(), 0.0777, 0.015);
  EXPECT_NEAR(c["parameters"]["b_from_r"].get<double>(), 0.0704, 0.015);
  EXPECT_GT(c["uncertainty"]["r_from_g"].get<double>(), 0.0);
  EXPECT_FALSE(c["description"].get<std::string>().empty());
  for (const char* f : {"report.json", "report.txt", "residuals.csv", "heldout_scatter.svg", "heldout_residuals.svg",
                        "candidates_step1.svg", "heldout_rmse_by_illuminant.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  // Camera causes are not tissue properties: the material converter routes them to the camera.
  auto t = ofl::tissue_corrections_from_report(j);
  EXPECT_TRUE(t.empty());
  ASSERT_EQ(t.instrument_causes.size(), 1u);
  EXPECT_EQ(t.instrument_causes[0], "crosstalk");
}
