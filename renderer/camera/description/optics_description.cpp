#include "renderer/camera/description/optics_description.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/image_file.h"

namespace ofl {

size_t MtfTable::nearest(double nm) const {
  size_t best = 0;
  for (size_t i = 1; i < wavelength_nm.size(); ++i)
    if (std::fabs(wavelength_nm[i] - nm) < std::fabs(wavelength_nm[best] - nm)) best = i;
  return best;
}

namespace {

MtfTable read_mtf_table(const std::filesystem::path& file) {
  CsvNumeric t = read_numeric_csv(file);
  int cw = t.require_column("wavelength_nm"), cf = t.require_column("frequency_cyc_per_mm"),
      cm = t.require_column("mtf");
  MtfTable m;
  m.file = file.string();
  auto fail = [&](size_t row, const char* col, const std::string& what) {
    throw InputError(file.string(), "line " + std::to_string(t.lines[row]) + " column " + col, what);
  };
  for (size_t r = 0; r < t.rows.size(); ++r) {
    double nm = t.rows[r][cw], f = t.rows[r][cf], v = t.rows[r][cm];
    if (!(nm > 0) || !std::isfinite(nm)) fail(r, "wavelength_nm", "expected a wavelength > 0 nm");
    if (!(f >= 0) || !std::isfinite(f)) fail(r, "frequency_cyc_per_mm", "expected a frequency >= 0");
    if (!(v >= -1 && v <= 1)) fail(r, "mtf", "expected an MTF value in [-1, 1]");
    if (m.wavelength_nm.empty() || m.wavelength_nm.back() != nm) {
      for (double w : m.wavelength_nm)
        if (w == nm) fail(r, "wavelength_nm", "rows of one wavelength must be together");
      m.wavelength_nm.push_back(nm);
      m.freq_cyc_per_mm.emplace_back();
      m.mtf.emplace_back();
    } else if (!(f > m.freq_cyc_per_mm.back().back())) {
      fail(r, "frequency_cyc_per_mm", "frequencies must increase within a wavelength");
    }
    m.freq_cyc_per_mm.back().push_back(f);
    m.mtf.back().push_back(v);
  }
  if (m.wavelength_nm.empty()) throw InputError(file.string(), "", "no MTF rows");
  for (size_t i = 0; i < m.wavelength_nm.size(); ++i)
    if (m.freq_cyc_per_mm[i].size() < 2 || !(m.freq_cyc_per_mm[i].back() > 0))
      throw InputError(file.string(), "wavelength_nm " + std::to_string(m.wavelength_nm[i]),
                       "needs at least two frequencies, the last above 0");
  return m;
}

// A PSF image: the first channel of an image file (EXR, TIFF, PNG ...), or a CSV whose rows after
// the header are the grid's rows. NaN or infinite values are errors; negative values (background
// subtraction noise) are set to zero; the sum must be positive.
PsfImage read_psf_image(const std::filesystem::path& file) {
  PsfImage p;
  auto bad = [&](const std::string& where, const std::string& what) { throw InputError(file.string(), where, what); };
  if (file.extension() == ".csv") {
    CsvNumeric t = read_numeric_csv(file);
    p.height = static_cast<int>(t.rows.size());
    p.width = static_cast<int>(t.header.size());
    for (size_t r = 0; r < t.rows.size(); ++r)
      for (size_t c = 0; c < t.rows[r].size(); ++c) {
        double v = t.rows[r][c];
        if (!std::isfinite(v))
          bad("line " + std::to_string(t.lines[r]) + " column " + std::to_string(c + 1), "PSF value is NaN or infinite");
        p.v.push_back(std::max(0.0, v));
      }
  } else {
    FloatImage img = read_image_file(file);
    p.width = img.width;
    p.height = img.height;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        double v = img.pixels[(static_cast<size_t>(y) * img.width + x) * img.channels];
        if (!std::isfinite(v))
          bad("pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")", "PSF value is NaN or infinite");
        p.v.push_back(std::max(0.0, v));
      }
  }
  double sum = 0;
  for (double v : p.v) sum += v;
  if (p.width < 1 || p.height < 1 || !(sum > 0)) bad("", "the PSF image holds no positive value");
  return p;
}

}  // namespace

size_t OpticsDescription::nearest_psf_image(double nm) const {
  size_t best = 0;
  for (size_t i = 1; i < psf_images.size(); ++i)
    if (std::fabs(psf_images[i].wavelength_nm - nm) < std::fabs(psf_images[best].wavelength_nm - nm)) best = i;
  return best;
}

OpticsDescription parse_optics(const JsonNode& n) {
  n.check_keys({"sensor_pixels", "sensor_offset_um", "focus_distance_mm", "diffraction", "defocus",
                "psf_extent_lambda_n", "psf_supersample", "mtf_file", "psf_images"});
  OpticsDescription o;
  o.enabled = true;
  JsonNode px = n.at("sensor_pixels");
  if (!px.is_array() || px.size() != 2) px.fail("expected [width, height] in pixels");
  o.sensor_width_px = px.at(size_t{0}).integer(1, 65536);
  o.sensor_height_px = px.at(size_t{1}).integer(1, 65536);
  if (auto off = n.find("sensor_offset_um")) {
    if (!off->is_array() || off->size() != 2) off->fail("expected [x, y] in micrometres");
    o.offset_x_um = off->at(size_t{0}).number(-1e6, 1e6);
    o.offset_y_um = off->at(size_t{1}).number(-1e6, 1e6);
  }
  if (auto f = n.find("focus_distance_mm")) o.focus_distance_mm = f->number(0.0, 1e12);
  o.diffraction = n.boolean_or("diffraction", o.diffraction);
  o.defocus = n.boolean_or("defocus", o.defocus);
  o.psf_extent_lambda_n = n.number_or("psf_extent_lambda_n", o.psf_extent_lambda_n, 2.0, 100.0);
  o.psf_supersample = n.integer_or("psf_supersample", o.psf_supersample, 1, 64);
  if (auto m = n.find("mtf_file")) o.mtf = m->read_file(read_mtf_table);
  if (auto pi = n.find("psf_images")) {
    if (o.mtf.wavelength_nm.size() > 0) pi->fail("give either mtf_file or psf_images, not both");
    if (!pi->is_array() || pi->size() == 0) pi->fail("expected a list of {\"wavelength_nm\", \"file\", \"pitch_um\"}");
    for (size_t i = 0; i < pi->size(); ++i) {
      JsonNode e = pi->at(i);
      e.check_keys({"wavelength_nm", "file", "pitch_um"});
      PsfImage img = e.at("file").read_file(read_psf_image);
      img.wavelength_nm = e.at("wavelength_nm").number(100.0, 5000.0);
      img.pitch_um = e.at("pitch_um").number(1e-3, 1e4);
      o.psf_images.push_back(std::move(img));
      o.psf_image_files.push_back(std::filesystem::absolute(e.at("file").existing_file()).string());
    }
  }
  return o;
}

nlohmann::json optics_to_json(const OpticsDescription& o) {
  nlohmann::json j = {{"sensor_pixels", {o.sensor_width_px, o.sensor_height_px}},
                      {"sensor_offset_um", {o.offset_x_um, o.offset_y_um}},
                      {"focus_distance_mm", o.focus_distance_mm},
                      {"diffraction", o.diffraction},
                      {"defocus", o.defocus},
                      {"psf_extent_lambda_n", o.psf_extent_lambda_n},
                      {"psf_supersample", o.psf_supersample}};
  if (!o.mtf.empty()) j["mtf_file"] = std::filesystem::absolute(o.mtf.file).string();  // raw.json is read elsewhere
  if (!o.psf_images.empty()) {
    j["psf_images"] = nlohmann::json::array();
    for (size_t i = 0; i < o.psf_images.size(); ++i)
      j["psf_images"].push_back({{"wavelength_nm", o.psf_images[i].wavelength_nm}, {"file", o.psf_image_files[i]},
                                 {"pitch_um", o.psf_images[i].pitch_um}});
  }
  return j;
}

}  // namespace ofl
