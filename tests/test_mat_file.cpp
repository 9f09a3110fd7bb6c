// .mat files through libmatio: a value tree written and read back unchanged, and ISETCam spectral
// files (wavelength, data) accepted wherever a spectrum CSV is, with errors naming the variable.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <unistd.h>

#include "renderer/camera/description/camera_description.h"
#include "renderer/core/errors/error.h"
#include "renderer/formats/mat_file.h"
#include "renderer/formats/mat_spectrum.h"
#include "renderer/spectral/spectra/spectrum.h"
#include "renderer/spectral/spectrum_json.h"

namespace ofl {
namespace {

std::filesystem::path tmp_dir() {
  auto d = std::filesystem::temp_directory_path() / ("ofl_mat_test_" + std::to_string(::getpid()));
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

TEST(MatFile, ValueTreeRoundTrip) {
  MatValue s = MatValue::structure();
  s.set("name", MatValue::string("patch 1"));
  s.set("wave", MatValue::vector({400, 410, 420}, true));
  std::vector<double> cube;
  for (int i = 0; i < 2 * 3 * 4; ++i) cube.push_back(0.25 * i - 1.0);
  s.set("cube", MatValue::array({2, 3, 4}, cube, true));
  MatValue inner = MatValue::structure();
  inner.set("x", MatValue::scalar(3.5));
  inner.set("empty", MatValue{});
  s.set("inner", inner);
  s.set("names", MatValue::cell_row({MatValue::string("r"), MatValue::string("g"), MatValue::string("b")}));
  auto file = tmp_dir() / "tree.mat";
  write_mat_file(file, {{"s", s}, {"k", MatValue::scalar(-2e-19)}});

  MatVariables vars = read_mat_file(file);
  ASSERT_EQ(vars.size(), 2u);
  EXPECT_EQ(vars[0].first, "s");
  EXPECT_EQ(vars[1].first, "k");
  EXPECT_EQ(vars[1].second.numbers, std::vector<double>{-2e-19});
  const MatValue& r = vars[0].second;
  ASSERT_EQ(r.kind, MatValue::Kind::kStruct);
  EXPECT_EQ(mat_require(file, r, "s", "name").text, "patch 1");
  const MatValue& w = mat_require(file, r, "s", "wave");
  EXPECT_EQ(w.dims, (std::vector<size_t>{3, 1}));
  EXPECT_EQ(w.numbers, (std::vector<double>{400, 410, 420}));
  const MatValue& c = mat_require(file, r, "s", "cube");
  EXPECT_TRUE(c.single);
  EXPECT_EQ(c.dims, (std::vector<size_t>{2, 3, 4}));
  EXPECT_EQ(c.numbers, cube);  // quarter steps are exact in single precision
  EXPECT_EQ(mat_scalar(file, mat_require(file, r, "s", "inner.x"), "s.inner.x"), 3.5);
  const MatValue& names = mat_require(file, r, "s", "names");
  ASSERT_EQ(names.cells.size(), 3u);
  EXPECT_EQ(names.cells[1].text, "g");
  EXPECT_FALSE(read_mat_variable(file, "nope").has_value());
  ASSERT_TRUE(read_mat_variable(file, "k").has_value());
  EXPECT_NE(input_error_of([&] { mat_require(file, r, "s", "inner.y"); }).find("s.inner.y: missing field"), std::string::npos);
}

TEST(MatFile, NotAMatFileIsAnInputError) {
  auto f = tmp_dir() / "broken.mat";
  std::ofstream(f) << "MATLAB 5.0 MAT-file, but not really";
  std::string e = input_error_of([&] { read_mat_file(f); });
  EXPECT_NE(e.find(f.string()), std::string::npos) << e;
  EXPECT_NE(e.find("not a MATLAB .mat file"), std::string::npos) << e;
}

// A MAT 4 file written by hand: 20-byte header (type 0 = little-endian double, rows, columns,
// imaginary flag, name length with its NUL), the name, the column-major data.
std::string mat4_variable(const std::string& name, uint32_t rows, uint32_t cols, const std::vector<double>& data,
                          uint32_t name_len = 0) {
  uint32_t h[5] = {0, rows, cols, 0, name_len ? name_len : uint32_t(name.size() + 1)};
  std::string b(reinterpret_cast<const char*>(h), sizeof h);
  b += name;
  b.push_back('\0');
  b.append(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(double));
  return b;
}

TEST(MatFile, Mat4IsReadAndItsSizesAreCheckedBeforeLibmatio) {
  auto ok = tmp_dir() / "v4.mat";
  std::ofstream(ok, std::ios::binary) << mat4_variable("wave", 1, 3, {400, 410, 420}) + mat4_variable("k", 1, 1, {-2.5});
  MatVariables vars = read_mat_file(ok);
  ASSERT_EQ(vars.size(), 2u);
  EXPECT_EQ(vars[0].first, "wave");
  EXPECT_EQ(vars[0].second.numbers, (std::vector<double>{400, 410, 420}));
  EXPECT_EQ(vars[1].second.numbers, std::vector<double>{-2.5});
  // fuzz_mat: 22 bytes whose name length field says 1.8 GB made libmatio's MAT 4 probe allocate it
  // (tests/fuzz/regressions/mat/mat4_name_length_1.8GB.mat); now an error before libmatio opens it.
  auto name = tmp_dir() / "v4_name.mat";
  std::ofstream(name, std::ios::binary) << mat4_variable("wave", 1, 3, {400, 410, 420}, 1872113791u);
  std::string e = input_error_of([&] { read_mat_file(name); });
  EXPECT_NE(e.find(name.string() + ": variable 1: name of 1872113791 bytes but only 29 bytes of the file are left"),
            std::string::npos) << e;
  // fuzz_mat (2026-11-26): a type word that must be byte-swapped (00 00 00 0a: type 10, machine
  // digit 0 = little-endian) before a name length 00 00 00 69 that libmatio then reads
  // little-endian: 1.76 GB allocated from a 150-byte file (regressions/mat/mat4_swapped_type_1.7GB.mat).
  auto swapped = tmp_dir() / "v4_swapped.mat";
  {
    std::string b = std::string("\0\0\0\x0a", 4) + std::string(12, '\0') + std::string("\0\0\0\x69", 4) + std::string(130, 'i');
    std::ofstream(swapped, std::ios::binary) << b;
  }
  e = input_error_of([&] { read_mat_file(swapped); });
  EXPECT_NE(e.find(swapped.string() + ": variable 1: name of 1761607680 bytes but only 130 bytes of the file are left"),
            std::string::npos) << e;
  // fuzz_mat (2026-11-26, second campaign): a file ending its 128-byte header in "MI" but with the
  // version bytes 00 01 (0x0001 in that byte order, not 5's 0x0100) is MAT 4 to libmatio, which read
  // the name length 00 74 79 70 from byte 16 and allocated 1.9 GB (regressions/mat/mi_header_version_0001.mat).
  auto mi = tmp_dir() / "mi_header.mat";
  {
    std::string b = std::string(12, '\0') + std::string("\0\x3f\0\0\0typ", 8) + std::string(104, ' ') + std::string("\0\x01MI", 4);
    ASSERT_EQ(b.size(), 128u);
    std::ofstream(mi, std::ios::binary) << b;
  }
  e = input_error_of([&] { read_mat_file(mi); });
  EXPECT_NE(e.find(mi.string() + ": variable 1: name of 1887007744 bytes but only 108 bytes of the file are left"), std::string::npos)
      << e;
  // fuzz_mat (2026-11-26, third campaign): a sparse MAT 4 variable (type 2) of 603979776 rows and 0
  // columns: libmatio sized its index array by the rows, 2.4 GB from 50 bytes
  // (regressions/mat/mat4_sparse_rows_2.4GB.mat). Sparse is checked as at least 3 columns.
  auto sparse = tmp_dir() / "v4_sparse.mat";
  {
    std::string b = std::string("\0\0\0\x02\0\0\0\x24", 8) + std::string(6, '\0') + std::string("\x18\0\x01\0\0\0", 6) +
                    std::string(30, '\0');
    std::ofstream(sparse, std::ios::binary) << b;
  }
  e = input_error_of([&] { read_mat_file(sparse); });
  EXPECT_NE(e.find(sparse.string() + ": variable 1: 603979776x3 sparse complex elements of 8 bytes but only"), std::string::npos) << e;
  // The second variable claims 100000 x 100000 doubles behind 8 bytes.
  auto data = tmp_dir() / "v4_data.mat";
  std::ofstream(data, std::ios::binary) << mat4_variable("wave", 1, 3, {400, 410, 420}) + mat4_variable("k", 100000, 100000, {1});
  e = input_error_of([&] { read_mat_file(data); });
  EXPECT_NE(e.find("variable 2: 100000x100000 elements of 8 bytes but only 8 bytes of the file are left"), std::string::npos) << e;
}

// The same spectrum as CSV and as an ISETCam .mat gives the same table everywhere a CSV is read.
TEST(MatSpectrum, MatEqualsCsvInSpectraAndCameraQe) {
  auto d = tmp_dir();
  std::vector<double> nm = {400, 450, 500, 550, 600, 650, 700};
  std::vector<std::vector<double>> qe = {{0.05, 0.04, 0.06, 0.12, 0.45, 0.50, 0.30},
                                         {0.10, 0.30, 0.55, 0.60, 0.20, 0.08, 0.05},
                                         {0.35, 0.55, 0.40, 0.10, 0.03, 0.02, 0.02}};
  write_spectrum_mat(d / "qe.mat", nm, qe, {"r", "g", "b"}, "test QE");
  {
    std::ofstream csv(d / "qe.csv");
    csv << "wavelength_nm,r,g,b\n";
    for (size_t i = 0; i < nm.size(); ++i) csv << nm[i] << "," << qe[0][i] << "," << qe[1][i] << "," << qe[2][i] << "\n";
  }
  for (const char* col : {"r", "g", "b"}) {
    SpectrumCsvOptions o;
    o.column = col;
    TabulatedSpectrum a = read_spectrum_csv(d / "qe.mat", o), b = read_spectrum_csv(d / "qe.csv", o);
    EXPECT_EQ(a.nm, b.nm);
    EXPECT_EQ(a.value, b.value) << col;
  }
  // A camera whose QE file is the .mat, columns found from filterNames as from a CSV header.
  nlohmann::json cam = JsonFile::load(std::string(OFL_SOURCE_DIR) + "/scenes/cameras/oraleye.json").doc();
  cam["sensor"]["qe"] = {{"file", "qe.mat"}};
  nlohmann::json cam_csv = cam;
  cam_csv["sensor"]["qe"]["file"] = "qe.csv";
  CameraDescription cm = parse_camera(JsonFile::from(cam, (d / "cam.json").string()).root());
  CameraDescription cc = parse_camera(JsonFile::from(cam_csv, (d / "cam.json").string()).root());
  for (int k = 0; k < 3; ++k)
    for (double w = 395; w <= 705; w += 2.5) EXPECT_EQ(cm.sensor.qe[k](w), cc.sensor.qe[k](w)) << k << " " << w;
  EXPECT_DOUBLE_EQ(cm.sensor.qe[1](500), 0.55);
}

TEST(MatSpectrum, SingleColumnRowDataAndScenesSpectrumForms) {
  auto d = tmp_dir();
  // data stored as a 1 x N row (a single spectrum), wavelength as a row: both accepted.
  write_mat_file(d / "refl.mat", {{"wavelength", MatValue::vector({400, 500, 600, 700})},
                                  {"data", MatValue::vector({0.2, 0.4, 0.6, 0.5})},
                                  {"comment", MatValue::string("reflectance")}});
  CsvNumeric t = read_spectrum_mat(d / "refl.mat");
  ASSERT_EQ(t.header, (std::vector<std::string>{"wavelength_nm", "data"}));
  EXPECT_EQ(t.rows[2], (std::vector<double>{600, 0.6}));
  nlohmann::json spec = "refl.mat";
  JsonNode n(&spec, (d / "scene.json").string(), "/materials/x/reflectance");
  Spectrum s = parse_spectrum(n, SpectrumKind::kReflectance);
  EXPECT_DOUBLE_EQ(s(550), 0.5);
  EXPECT_DOUBLE_EQ(s(750), 0.5);  // reflectance tables clamp outside, as from a CSV
}

TEST(MatSpectrum, ErrorsNameTheFileAndVariable) {
  auto d = tmp_dir();
  auto f1 = d / "nodata.mat";
  write_mat_file(f1, {{"wavelength", MatValue::vector({400, 500})}, {"values", MatValue::vector({1, 2})}});
  std::string e1 = input_error_of([&] { read_spectrum_csv(f1); });
  EXPECT_NE(e1.find(f1.string() + ": variable \"data\": missing"), std::string::npos) << e1;
  EXPECT_NE(e1.find("wavelength, values"), std::string::npos) << e1;  // says what the file has

  auto f2 = d / "nowave.mat";
  write_mat_file(f2, {{"data", MatValue::vector({1, 2})}});
  EXPECT_NE(input_error_of([&] { read_spectrum_csv(f2); }).find("variable \"wavelength\": missing"), std::string::npos);

  auto f3 = d / "nan.mat";
  write_mat_file(f3, {{"wavelength", MatValue::vector({400, 500, 600})}, {"data", MatValue::vector({0.1, std::nan(""), 0.3})}});
  std::string e3 = input_error_of([&] { read_spectrum_csv(f3); });
  EXPECT_NE(e3.find("data row 2"), std::string::npos) << e3;
  EXPECT_NE(e3.find("NaN"), std::string::npos) << e3;

  auto f4 = d / "size.mat";
  write_mat_file(f4, {{"wavelength", MatValue::vector({400, 500, 600})}, {"data", MatValue::array({2, 2}, {1, 2, 3, 4})}});
  EXPECT_NE(input_error_of([&] { read_spectrum_csv(f4); }).find("variable \"data\": is 2 x 2 but wavelength has 3 values"),
            std::string::npos);

  auto f5 = d / "order.mat";
  write_mat_file(f5, {{"wavelength", MatValue::vector({400, 600, 500})}, {"data", MatValue::vector({1, 2, 3})}});
  EXPECT_NE(input_error_of([&] { read_spectrum_csv(f5); }).find("variable \"wavelength\": wavelengths must increase"),
            std::string::npos);

  // Through a scene entry: the message names the .mat and the scene field that referred to it.
  nlohmann::json spec = {{"type", "csv"}, {"file", "nodata.mat"}};
  JsonNode n(&spec, (d / "scene.json").string(), "/lights/0/spd");
  std::string e6 = input_error_of([&] { parse_spectrum(n, SpectrumKind::kEmission); });
  EXPECT_NE(e6.find("variable \"data\""), std::string::npos) << e6;
  EXPECT_NE(e6.find("named by " + (d / "scene.json").string() + " /lights/0/spd/file"), std::string::npos) << e6;
}

}  // namespace
}  // namespace ofl
