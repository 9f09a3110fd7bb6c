// camera.json: the presets load, every bad field is reported with its file and JSON path, and the
// self-contained copy written into raw.json sidecars reads back as the same camera.
#include <gtest/gtest.h>

#include <fstream>

#include "camera_test_util.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"

using namespace ofl;
using namespace ofl::testing;

namespace {
const std::filesystem::path kPresets = std::filesystem::path(OFL_SOURCE_DIR) / "scenes" / "cameras";

std::string minimal_sensor(const std::string& extra = "") {
  return R"("sensor": {"pixel_pitch_um": 3, "qe": {"R": 0.5, "G": 0.5, "B": 0.5}, "exposure_s": 0.01,
            "system_gain_dn_per_e": 0.2, "full_well_e": 10000)" + extra + "}";
}

// Parses `text` as a camera file and returns the InputError's field ("" when it parsed).
std::string error_field(const std::string& text, std::string* file = nullptr, std::string* what = nullptr) {
  auto dir = scratch("desc");
  auto p = dir / "camera.json";
  std::ofstream(p) << text;
  try {
    load_camera(p);
  } catch (const InputError& e) {
    if (file) *file = e.file();
    if (what) *what = e.what();
    return e.field();
  }
  return "";
}
}  // namespace

TEST(CameraDescription, PresetsLoadWithTheirFilters) {
  CameraDescription oe = load_camera(kPresets / "oraleye.json");
  ASSERT_EQ(oe.filters.filters.size(), 2u);
  EXPECT_EQ(oe.filters.filters[0].filter.kind, OpticalFilter::Kind::kLongpass);
  EXPECT_EQ(oe.filters.filters[0].filter.edge_nm, 475);
  EXPECT_EQ(oe.filters.filters[0].position, FilterPosition::kFrontOfLens);
  EXPECT_EQ(oe.filters.filters[1].filter.kind, OpticalFilter::Kind::kShortpass);
  EXPECT_EQ(oe.filters.filters[1].filter.edge_nm, 700);
  EXPECT_EQ(oe.filters.filters[1].position, FilterPosition::kAtSensor);
  EXPECT_EQ(oe.sensor.cfa, CfaPattern::kRGGB);
  // The QE is the shipped MT9V024 table: compare with the CSV row at 550 nm.
  CsvNumeric qe = read_numeric_csv(std::filesystem::path(OFL_SOURCE_DIR) / "assets/sensors/MT9V024_RGB.csv");
  for (size_t r = 0; r < qe.rows.size(); ++r)
    if (qe.rows[r][0] == 550) {
      EXPECT_NEAR(oe.sensor.qe[kRed](550), qe.rows[r][1], 1e-12);
      EXPECT_NEAR(oe.sensor.qe[kGreen](550), qe.rows[r][2], 1e-12);
      EXPECT_NEAR(oe.sensor.qe[kBlue](550), qe.rows[r][3], 1e-12);
    }
  // 37 C against a 25 C reference with 6 C doubling: 4x the dark current.
  EXPECT_NEAR(oe.sensor.dark_current_at_temperature(), 4 * oe.sensor.dark_current_e_per_s, 1e-9);

  CameraDescription plain = load_camera(kPresets / "plain_rgb.json");
  ASSERT_EQ(plain.filters.filters.size(), 1u);
  EXPECT_EQ(plain.filters.filters[0].filter.kind, OpticalFilter::Kind::kMeasured);
  EXPECT_LT(plain.filters.filters[0].filter.transmittance(800), 0.01);
  EXPECT_GT(plain.filters.filters[0].filter.transmittance(500), 0.9);
  EXPECT_EQ(plain.sensor.cfa, CfaPattern::kGRBG);
}

TEST(CameraDescription, ErrorsNameFileAndField) {
  std::string file, what;
  EXPECT_EQ(error_field("{" + minimal_sensor() + "}"), "");
  EXPECT_EQ(error_field("{" + minimal_sensor(R"(, "ful_well_e": 3)") + "}"), "/sensor/ful_well_e");
  EXPECT_EQ(error_field("{" + minimal_sensor(R"(, "cfa": "RGBW")") + "}"), "/sensor/cfa");
  EXPECT_EQ(error_field(R"({"lens": {"magnification": 0.2}, )" + minimal_sensor() + "}"), "/lens/magnification");
  EXPECT_EQ(error_field("{" + minimal_sensor(R"(, "conversion_gain_uV_per_e": 50, "adc_uV_per_dn": 250)") + "}"),
            "/sensor/system_gain_dn_per_e");
  EXPECT_EQ(error_field(R"({"sensor": {"pixel_pitch_um": 3, "qe": {"R": 0.5, "G": 0.5, "B": 0.5},
            "system_gain_dn_per_e": 0.2, "full_well_e": 10000}})"),
            "/sensor/exposure_s");
  EXPECT_EQ(error_field("{" + minimal_sensor(R"(, "bit_depth": 20)") + "}"), "/sensor/bit_depth");
  EXPECT_EQ(error_field("{" + minimal_sensor(R"(, "black_level_dn": 300, "bit_depth": 8)") + "}"), "/sensor/black_level_dn");
  EXPECT_EQ(error_field(R"({"filters": [{"type": "notch", "edge_nm": 500}], )" + minimal_sensor() + "}"), "/filters/0/type");
  EXPECT_EQ(error_field(R"({"filters": [{"type": "longpass", "edge_nm": 500, "position": "behind"}], )" + minimal_sensor() + "}"),
            "/filters/0/position");
  EXPECT_EQ(error_field(R"({"format_version": 2, )" + minimal_sensor() + "}"), "/format_version");
  EXPECT_EQ(error_field(R"({"format": "oralfluor-camera", "version": 2, )" + minimal_sensor() + "}"), "/version");
  EXPECT_EQ(error_field(R"({"format": "oralfluor-scene", "version": 1, )" + minimal_sensor() + "}"), "/format");
  EXPECT_EQ(error_field("{" + minimal_sensor() + ", \"seed\": -1}"), "/seed");
  // Malformed JSON names the line.
  EXPECT_EQ(error_field("{\n\"sensor\": {,\n}"), "line 2 column 12");

  // A QE table with NaN is reported with the CSV's own name and line.
  auto dir = scratch("desc_nan");
  std::ofstream(dir / "qe.csv") << "wavelength_nm,r,g,b\n400,0.1,0.2,0.3\n410,0.1,NaN,0.3\n";
  std::ofstream(dir / "camera.json") << R"({"sensor": {"pixel_pitch_um": 3, "qe": {"file": "qe.csv"}, "exposure_s": 0.01,
      "system_gain_dn_per_e": 0.2, "full_well_e": 10000}})";
  try {
    load_camera(dir / "camera.json");
    FAIL() << "accepted a QE with NaN";
  } catch (const InputError& e) {
    EXPECT_EQ(std::filesystem::path(e.file()).filename(), "qe.csv");
    EXPECT_EQ(e.field(), "line 3 column \"g\"");
  }
  // QE in percent is caught.
  std::ofstream(dir / "qe.csv") << "wavelength_nm,r,g,b\n400,10,20,30\n410,10,20,30\n";
  EXPECT_THROW(load_camera(dir / "camera.json"), InputError);
}

TEST(CameraDescription, SidecarCopyReadsBackAsTheSameCamera) {
  CameraDescription a = load_camera(kPresets / "oraleye.json");
  nlohmann::json j = camera_to_json(a, 395, 705);
  JsonFile f = JsonFile::from(j, "sidecar");
  CameraDescription b = parse_camera(f.root());
  for (double nm = 396; nm < 705; nm += 1.7)
    for (double th : {0.0, 0.3, 0.6})
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(system_qe(b, c, nm, th, th), system_qe(a, c, nm, th, th), 1e-12) << nm << " " << th << " " << c;
  EXPECT_EQ(b.sensor.cfa, a.sensor.cfa);
  EXPECT_EQ(b.sensor.full_well_e, a.sensor.full_well_e);
  EXPECT_EQ(b.sensor.system_gain_dn_per_e, a.sensor.system_gain_dn_per_e);
  EXPECT_EQ(b.sensor.prnu, a.sensor.prnu);
  EXPECT_EQ(b.sensor.fixed_pattern_seed, a.sensor.fixed_pattern_seed);
  EXPECT_EQ(b.lens.f_number, a.lens.f_number);
  // A measured filter keeps its table, so it shifts the same way.
  CameraDescription p = load_camera(kPresets / "plain_rgb.json");
  CameraDescription q = parse_camera(JsonFile::from(camera_to_json(p, 395, 705), "sidecar").root());
  for (double nm = 600; nm < 760; nm += 3.3)
    EXPECT_NEAR(q.filters.transmittance(nm, 0, 0.5), p.filters.transmittance(nm, 0, 0.5), 1e-12) << nm;
}
