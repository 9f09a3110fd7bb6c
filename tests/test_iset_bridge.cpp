// The ISETCam bridge: a spectral image exported as an ISETCam scene (every field read back with
// libmatio and checked against the source and closed forms), the scene read back, and an ISETCam
// sensor struct imported as a camera (every mapped field against the ISETCam definitions).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>

#include "renderer/camera/description/camera_description.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/interop/iset_scene.h"
#include "renderer/formats/iset_sensor.h"
#include "renderer/formats/mat_file.h"
#include "renderer/formats/mat_spectrum.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/color.h"
#include "tests/cli_runner.h"

namespace ofl {
namespace {

constexpr double kH = 6.62607015e-34, kC = 299792458.0, kPiD = 3.14159265358979323846;

std::filesystem::path tmp_dir() {
  auto d = std::filesystem::temp_directory_path() / ("ofl_iset_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

std::string input_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.describe();
  }
  return "no error";
}

// 6 x 4 pixels, 7 bands 400..700 nm, a plane 0.2 m away seen by a 30 degree (vertical) pinhole,
// pixel (0, 0) misses it; LED irradiance i at pixel i; a trapezoid LED spectrum 420-480 nm.
SpectralImage test_image(const std::string& led_json) {
  SpectralImage img;
  img.resize(6, 4, {400, 450, 500, 550, 600, 650, 700});
  img.fluorescence.assign(img.data.size(), 0.0f);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x)
      for (int b = 0; b < 7; ++b) {
        img.pixel(x, y)[b] = float(1e-3 * (1 + x + 10 * y) * (b + 1));
        img.fluorescence[(y * 6 + x) * 7 + b] = float(1e-4 * (x + 1));
      }
  std::vector<float> mat(24, 0.0f), depth(24), irr(24);
  double tv = std::tan(15.0 * kPiD / 180.0), th = tv * 6.0 / 4.0;
  for (int i = 0; i < 24; ++i) {
    int x = i % 6, y = i / 6;
    double u = (2.0 * (x + 0.5) / 6 - 1) * th, v = (1 - 2.0 * (y + 0.5) / 4) * tv;
    depth[i] = float(0.2 * std::sqrt(1 + u * u + v * v));  // ray length to the plane z = 0.2
    irr[i] = float(i);
  }
  mat[0] = -1;
  img.aovs["aov.material"] = mat;
  img.aovs["aov.depth"] = depth;
  img.aovs["aov.irradiance"] = irr;
  img.attributes["oralfluor.vfov_deg"] = "30";
  img.attributes["oralfluor.seed"] = "7";
  img.attributes["oralfluor.excitation_spd"] = led_json;
  return img;
}

MatValue iset_sensor();  // an ISETCam sensor struct (below)

const std::string kTrapezoidLed = R"({"nm": [350, 420, 430, 470, 480, 800], "W_per_sr_nm": [0, 0, 0.02, 0.02, 0, 0]})";

TEST(IsetScene, EveryFieldMatchesTheSource) {
  SpectralImage img = test_image(kTrapezoidLed);
  auto file = tmp_dir() / "scene.mat";
  IsetScene s = make_iset_scene(img, {}, "render/radiance.exr");
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  write_iset_scene(file, s);

  auto v = read_mat_variable(file, "scene");
  ASSERT_TRUE(v.has_value());
  const MatValue& sc = *v;
  const std::string f = file.string();
  EXPECT_EQ(mat_require(f, sc, "scene", "type").text, "scene");
  EXPECT_EQ(mat_require(f, sc, "scene", "name").text, "radiance");
  EXPECT_EQ(mat_require(f, sc, "scene", "spectrum.wave").numbers, img.band_nm);
  EXPECT_EQ(mat_require(f, sc, "scene", "spectrum.wave").dims, (std::vector<size_t>{7, 1}));
  EXPECT_EQ(mat_scalar(f, mat_require(f, sc, "scene", "magnification"), ""), 1.0);
  double hfov = 2 * std::atan(std::tan(15.0 * kPiD / 180.0) * 1.5) * 180.0 / kPiD;
  EXPECT_NEAR(mat_scalar(f, mat_require(f, sc, "scene", "wAngular"), ""), hfov, 1e-12);
  EXPECT_NEAR(mat_scalar(f, mat_require(f, sc, "scene", "distance"), ""), 0.2, 1e-6);  // the plane's distance

  // Photons: rows x cols x wave, column-major, W -> photons with lambda / (h c).
  const MatValue& ph = mat_require(f, sc, "scene", "data.photons");
  ASSERT_EQ(ph.dims, (std::vector<size_t>{4, 6, 7}));
  EXPECT_TRUE(ph.single);
  double sum = 0;
  for (int b = 0; b < 7; ++b)
    for (int x = 0; x < 6; ++x)
      for (int y = 0; y < 4; ++y) {
        float expect = float(double(img.pixel(x, y)[b]) * img.band_nm[b] * 1e-9 / (kH * kC));
        float got = float(ph.numbers[size_t(b) * 24 + x * 4 + y]);
        EXPECT_EQ(got, expect) << x << "," << y << "," << b;
        sum += got;
      }
  EXPECT_DOUBLE_EQ(s.photon_sum, sum);
  EXPECT_EQ(mat_scalar(f, mat_require(f, sc, "scene", "data.bitDepth"), ""), 32.0);

  // Luminance: 683 lm/W x sum L ybar dlambda.
  ColorMatching cmf = cie1931_on_bands(img.band_lo(), img.band_hi());
  const MatValue& lum = mat_require(f, sc, "scene", "data.luminance");
  ASSERT_EQ(lum.dims, (std::vector<size_t>{4, 6}));
  double y_expect = 0;
  for (int b = 0; b < 7; ++b) y_expect += img.pixel(5, 3)[b] * cmf.y[b] * 50.0;
  EXPECT_NEAR(lum.numbers[5 * 4 + 3], 683.0 * y_expect, 1e-9 * 683.0 * y_expect);

  // Illuminant: white Lambertian radiance at the median irradiance (pixels 1..23 -> 12 W/m^2).
  // Band averages of the trapezoid (integral 1 W/sr): 400 nm 0.025/50, 450 nm 0.95/50, 500 nm 0.025/50.
  const MatValue& il = mat_require(f, sc, "scene", "illuminant");
  EXPECT_EQ(mat_require(f, il, "illuminant", "type").text, "illuminant");
  EXPECT_EQ(mat_require(f, il, "illuminant", "spectrum.wave").numbers, img.band_nm);
  std::vector<double> il_ph = mat_require(f, il, "illuminant", "data.photons").numbers;
  std::vector<double> avg = {0.025 / 50, 0.95 / 50, 0.025 / 50, 0, 0, 0, 0};
  for (int b = 0; b < 7; ++b) {
    double expect = 12.0 * avg[b] / 1.0 / kPiD * img.band_nm[b] * 1e-9 / (kH * kC);
    EXPECT_NEAR(il_ph[b], expect, 1e-6 * 12.0 * 0.019 / kPiD * 450e-9 / (kH * kC)) << b;
  }
  // Metadata: the fluorescent part in photons, and the oralfluor header strings.
  const MatValue& fl = mat_require(f, sc, "scene", "metadata.fluorescencePhotons");
  EXPECT_EQ(float(fl.numbers[3 * 24 + 2 * 4 + 1]), float(double(float(1e-4 * 3)) * 550e-9 / (kH * kC)));  // x = 2, y = 1, 550 nm
  EXPECT_EQ(mat_require(f, sc, "scene", "metadata.seed").text, "7");
}

TEST(IsetScene, ReadBackGivesTheRadiance) {
  SpectralImage img = test_image(kTrapezoidLed);
  auto file = tmp_dir() / "roundtrip.mat";
  write_iset_scene(file, make_iset_scene(img, {"patch", 0.5, std::nullopt}, "x.exr"));
  SpectralImage back = read_iset_scene(file);
  ASSERT_EQ(back.width, 6);
  ASSERT_EQ(back.height, 4);
  EXPECT_EQ(back.band_nm, img.band_nm);
  for (size_t i = 0; i < img.data.size(); ++i) EXPECT_NEAR(back.data[i], img.data[i], 2e-7 * img.data[i]) << i;
  EXPECT_NEAR(std::stod(back.attributes.at("oralfluor.vfov_deg")), 30.0, 1e-5);
  EXPECT_NEAR(std::stod(back.attributes.at("oralfluor.iset_distance_m")), 0.5, 1e-9);
}

TEST(IsetScene, ImportOfAnExportRestoresEverythingTheExrHad) {
  SpectralImage img = test_image(kTrapezoidLed);
  img.attributes["emissiveUnits"] = "W.m^-2.sr^-1";
  img.attributes["oralfluor.scene"] = "scenes/x.json";
  auto d = tmp_dir();
  write_spectral_exr(d / "orig.exr", img);
  auto r = test::run_cli("export-iset " + (d / "orig.exr").string() + " -o " + (d / "rt.mat").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = test::run_cli("import-iset " + (d / "rt.mat").string() + " -o " + (d / "back.exr").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  SpectralImage a = read_spectral_exr(d / "orig.exr"), b = read_spectral_exr(d / "back.exr");
  ASSERT_EQ(b.width, a.width);
  ASSERT_EQ(b.height, a.height);
  EXPECT_EQ(b.band_nm, a.band_nm);
  // W -> photons (single) -> W: two roundings of a float.
  for (size_t i = 0; i < a.data.size(); ++i) EXPECT_NEAR(b.data[i], a.data[i], 2.5e-7 * a.data[i]) << i;
  ASSERT_EQ(b.fluorescence.size(), a.fluorescence.size());
  for (size_t i = 0; i < a.fluorescence.size(); ++i) EXPECT_NEAR(b.fluorescence[i], a.fluorescence[i], 2.5e-7 * a.fluorescence[i]) << i;
  ASSERT_EQ(b.aovs.size(), a.aovs.size());
  for (auto& [k, v] : a.aovs) EXPECT_EQ(b.aovs.at(k), v) << k;  // stored as single: exact
  for (auto& [k, v] : a.attributes) EXPECT_EQ(b.attributes.at(k), v) << k;
  EXPECT_EQ(b.attributes.at("oralfluor.iset_source"), (d / "rt.mat").string());
  // A scene ISETCam made (no oralfluor fields) still imports: radiance only.
  MatValue sc = *read_mat_variable(d / "rt.mat", "scene");
  sc.field("metadata")->fields.clear();
  write_mat_file(d / "plain.mat", {{"scene", sc}});
  SpectralImage c = read_iset_scene(d / "plain.mat");
  EXPECT_TRUE(c.fluorescence.empty());
  EXPECT_TRUE(c.aovs.empty());
  EXPECT_NEAR(std::stod(c.attributes.at("oralfluor.vfov_deg")), 30.0, 1e-12);
  // A damaged AOV is named.
  sc = *read_mat_variable(d / "rt.mat", "scene");
  sc.field("metadata")->field("aov")->fields[0].second = MatValue::array({2, 2}, {1, 2, 3, 4}, true);
  write_mat_file(d / "bad_aov.mat", {{"scene", sc}});
  std::string e = input_error_of([&] { read_iset_scene(d / "bad_aov.mat"); });
  EXPECT_NE(e.find("scene.metadata.aov.depth: expected 4 x 6"), std::string::npos) << e;
}

TEST(IsetScene, ImportRefusesAnOutputOfTheOtherKind) {
  // A scene becomes an EXR, a sensor a camera file: the wrong extension is exit 2 and no file.
  auto d = tmp_dir();
  write_iset_scene(d / "kind_scene.mat", make_iset_scene(test_image(kTrapezoidLed), {}, "x.exr"));
  std::filesystem::remove(d / "camera.json");
  auto r = test::run_cli("import-iset " + (d / "kind_scene.mat").string() + " -o " + (d / "camera.json").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("camera.json: -o: the input is an ISETCam scene, which becomes a spectral EXR"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(d / "camera.json"));
  write_mat_file(d / "kind_sensor.mat", {{"sensor", iset_sensor()}});
  std::filesystem::remove(d / "sensor.exr");
  r = test::run_cli("import-iset " + (d / "kind_sensor.mat").string() + " -o " + (d / "sensor.exr").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("sensor.exr: -o: the input is an ISETCam sensor"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(d / "sensor.exr"));
}

TEST(IsetSpectrum, PaddedColumnNamesMatchWithoutTheSpaces) {
  // ISETCam's SixLEDs.mat names its columns ' led525' and so on.
  auto file = tmp_dir() / "six.mat";
  write_spectrum_mat(file, {400, 500, 600}, {{0, 1, 0}, {1, 0, 0}}, {" led525", "led450  "});
  CsvNumeric t = read_spectrum_table(file);
  EXPECT_EQ(t.column("led525"), 1);
  EXPECT_EQ(t.column(" led525"), 1);
  EXPECT_EQ(t.column("led450"), 2);
  EXPECT_EQ(t.rows[1][t.column("led525")], 1.0);
}

TEST(IsetScene, LightOutsideTheBandsIsReportedAndMissingGeometryRefused) {
  // 360-380 nm LED: only its top ramp reaches the first band (from 375 nm).
  SpectralImage img = test_image(R"({"nm": [350, 360, 380, 390, 800], "W_per_sr_nm": [0, 0.02, 0.02, 0, 0]})");
  IsetScene s = make_iset_scene(img, {}, "x.exr");
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings[0].find("of the LED power lies outside the image's bands (375-725 nm)"), std::string::npos) << s.warnings[0];
  img.aovs.erase("aov.depth");
  EXPECT_NE(input_error_of([&] { make_iset_scene(img, {}, "x.exr"); }).find("x.exr: aov.depth: the EXR has no depth"),
            std::string::npos);
  EXPECT_EQ(make_iset_scene(img, {"", 1.5, std::nullopt}, "x.exr").distance_m, 1.5);  // given instead
}

TEST(IsetScene, CliExportsARenderedExr) {
  auto d = tmp_dir();
  SpectralImage img = test_image(kTrapezoidLed);
  auto exr = d / "cli.exr";
  write_spectral_exr(exr, img);
  auto out = d / "cli_scene.mat";
  auto r = test::run_cli("export-iset " + exr.string() + " -o " + out.string() + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto v = read_mat_variable(out, "scene");
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(mat_require(out.string(), *v, "scene", "data.photons").dims, (std::vector<size_t>{4, 6, 7}));
  auto bad = test::run_cli("export-iset " + (d / "missing.exr").string());
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
}

// An ISETCam sensor as sensorCreate builds it (fields as pixelSet / sensorSet store them).
MatValue iset_sensor() {
  std::vector<double> wave = {400, 450, 500, 550, 600, 650, 700};
  std::vector<double> g = {0.05, 0.3, 0.8, 0.9, 0.3, 0.1, 0.05}, r = {0.02, 0.02, 0.05, 0.1, 0.8, 0.9, 0.7},
                      b = {0.6, 0.9, 0.5, 0.1, 0.02, 0.02, 0.05};
  std::vector<double> filters = g;  // filterNames order g, r, b
  filters.insert(filters.end(), r.begin(), r.end());
  filters.insert(filters.end(), b.begin(), b.end());
  MatValue s = MatValue::structure();
  s.set("name", MatValue::string("test sensor"));
  s.set("type", MatValue::string("sensor"));
  MatValue px = MatValue::structure();
  px.set("name", MatValue::string("aps"));
  px.set("type", MatValue::string("pixel"));
  px.set("width", MatValue::scalar(2.8e-6));
  px.set("height", MatValue::scalar(2.8e-6));
  px.set("widthGap", MatValue::scalar(0.2e-6));
  px.set("heightGap", MatValue::scalar(0.2e-6));
  px.set("pdWidth", MatValue::scalar(2.4e-6));
  px.set("pdHeight", MatValue::scalar(2.4e-6));
  px.set("conversionGain", MatValue::scalar(1e-4));
  px.set("voltageSwing", MatValue::scalar(1.0));
  px.set("darkVoltage", MatValue::scalar(1e-3));
  px.set("readNoise", MatValue::scalar(1e-3));
  MatValue pspec = MatValue::structure();
  pspec.set("wave", MatValue::vector(wave, true));
  px.set("spectrum", pspec);
  px.set("spectralQE", MatValue::vector({0.9, 0.9, 0.95, 0.95, 0.9, 0.8, 0.7}, true));
  s.set("pixel", px);
  MatValue spec = MatValue::structure();
  spec.set("wave", MatValue::vector(wave, true));
  s.set("spectrum", spec);
  MatValue color = MatValue::structure();
  color.set("filterSpectra", MatValue::array({7, 3}, filters));
  color.set("filterNames", MatValue::cell_row({MatValue::string("gDefault"), MatValue::string("rDefault"), MatValue::string("bDefault")}));
  color.set("irFilter", MatValue::vector({1, 1, 1, 1, 1, 0.9, 0.5}, true));
  s.set("color", color);
  MatValue cfa = MatValue::structure();
  cfa.set("pattern", MatValue::array({2, 2}, {1, 3, 2, 1}));  // [g r; b g]: GRBG
  s.set("cfa", cfa);
  s.set("sigmaGainFPN", MatValue::scalar(0.5));
  s.set("sigmaOffsetFPN", MatValue::scalar(2e-3));
  s.set("analogGain", MatValue::scalar(2.0));
  s.set("analogOffset", MatValue::scalar(0.01));
  MatValue q = MatValue::structure();
  q.set("method", MatValue::string("linear"));
  q.set("bits", MatValue::scalar(10));
  s.set("quantization", q);
  s.set("integrationTime", MatValue::scalar(0.02));
  s.set("AE", MatValue::scalar(0));
  s.set("noiseFlag", MatValue::scalar(2));
  s.set("rows", MatValue::scalar(100));
  s.set("cols", MatValue::scalar(120));
  return s;
}

TEST(IsetSensor, EveryMappedFieldMatchesTheSensor) {
  auto file = tmp_dir() / "sensor.mat";
  MatValue s = iset_sensor();
  write_mat_file(file, {{"sensor", s}});
  CameraDescription cam = load_camera(file);  // a .mat stands where a camera.json does
  const SensorDescription& se = cam.sensor;
  EXPECT_EQ(cam.name, "test sensor");
  EXPECT_NEAR(se.pixel_pitch_um, 3.0, 1e-9);
  EXPECT_NEAR(se.fill_factor, 2.4 * 2.4 / 9.0, 1e-12);
  EXPECT_EQ(cfa_name(se.cfa), "GRBG");
  EXPECT_NEAR(se.full_well_e, 1.0 / 1e-4, 1e-6);       // voltageSwing / conversionGain
  EXPECT_NEAR(se.read_noise_e, 1e-3 / 1e-4, 1e-9);     // volts / (V/e-)
  EXPECT_NEAR(se.dark_current_e_per_s, 10.0, 1e-9);
  EXPECT_NEAR(se.dsnu_e, 20.0, 1e-9);
  EXPECT_NEAR(se.prnu, 0.005, 1e-12);
  EXPECT_EQ(se.bit_depth, 10);
  EXPECT_NEAR(se.system_gain_dn_per_e, 1e-4 * 1024 / 1.0, 1e-12);  // conversionGain / (swing / 2^bits)
  EXPECT_NEAR(se.analog_gain, 0.5, 1e-12);              // ISETCam divides volts by analogGain
  EXPECT_EQ(se.black_level_dn, 5);                      // 0.01 V / 2 / (1 V / 1024) = 5.12
  EXPECT_EQ(se.exposure_s, 0.02);
  EXPECT_TRUE(cam.noise);
  // Spectral QE = filter x IR filter x photodetector QE, channel by channel.
  const std::vector<double> wave = {400, 450, 500, 550, 600, 650, 700};
  const std::vector<double>& f = mat_require("", s, "sensor", "color.filterSpectra").numbers;
  const std::vector<double>& ir = mat_require("", s, "sensor", "color.irFilter").numbers;
  const std::vector<double>& pd = mat_require("", s, "sensor", "pixel.spectralQE").numbers;
  const int channel_of_column[3] = {1, 0, 2};  // g, r, b
  for (int k = 0; k < 3; ++k)
    for (size_t i = 0; i < wave.size(); ++i)
      EXPECT_NEAR(se.qe[channel_of_column[k]](wave[i]), f[k * 7 + i] * ir[i] * pd[i], 1e-12) << k << " " << wave[i];
  EXPECT_EQ(se.qe[0](390), 0.0);  // zero outside the sensor's wavelengths
}

TEST(IsetSensor, UnsupportedSensorsAreRefusedNamingTheField) {
  auto d = tmp_dir();
  MatValue four = iset_sensor();
  MatValue* color = four.field("color");
  color->set("filterSpectra", MatValue::array({7, 4}, std::vector<double>(28, 0.5)));
  color->set("filterNames", MatValue::cell_row({MatValue::string("w"), MatValue::string("r"), MatValue::string("g"),
                                                MatValue::string("b")}));
  write_mat_file(d / "rgbw.mat", {{"sensor", four}});
  std::string e1 = input_error_of([&] { import_iset_sensor(d / "rgbw.mat"); });
  EXPECT_NE(e1.find("sensor.color.filterNames: oralfluor models RGB sensors"), std::string::npos) << e1;

  MatValue nocg = iset_sensor();
  nocg.field("pixel")->fields.erase(nocg.field("pixel")->fields.begin() + 8);  // conversionGain
  write_mat_file(d / "nocg.mat", {{"sensor", nocg}});
  std::string e2 = input_error_of([&] { load_camera(d / "nocg.mat"); });
  EXPECT_NE(e2.find((d / "nocg.mat").string() + ": sensor.pixel.conversionGain: missing field"), std::string::npos) << e2;

  write_mat_file(d / "none.mat", {{"x", MatValue::scalar(1)}});
  EXPECT_NE(input_error_of([&] { import_iset_sensor(d / "none.mat"); }).find("variable \"sensor\": missing"), std::string::npos);
  auto r = test::run_cli("import-iset " + (d / "none.mat").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(IsetSensor, CliImportWritesACameraTheCameraCommandLoads) {
  auto d = tmp_dir();
  write_mat_file(d / "s.mat", {{"sensor", iset_sensor()}});
  auto r = test::run_cli("import-iset " + (d / "s.mat").string() + " -o " + (d / "cam.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  CameraDescription a = load_camera(d / "cam.json"), b = load_camera(d / "s.mat");
  EXPECT_EQ(a.sensor.full_well_e, b.sensor.full_well_e);
  EXPECT_EQ(cfa_name(a.sensor.cfa), cfa_name(b.sensor.cfa));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(a.sensor.qe[k](537.0), b.sensor.qe[k](537.0));
}

}  // namespace
}  // namespace ofl
