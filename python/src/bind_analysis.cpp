// Chromaticity of raw mosaics, the fluorophore reference lines (figure 5 of the OralEye paper) and
// the fluorophore library with its EEMs as arrays.
#include <filesystem>

#include "python/src/common.h"
#include "renderer/analysis/chroma_reference.h"
#include "renderer/analysis/chromaticity.h"
#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/core/errors/error.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl::python {
namespace {

// A 1-D list or array of finite numbers, or InputError naming `what`.
std::vector<double> number_list(const py::handle& obj, const std::string& what) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || py::isinstance<py::str>(obj) || a.ndim() != 1) throw InputError("", what, "expected a list or 1-D array of numbers, got " + type_name(obj));
  std::vector<double> v(a.data(), a.data() + a.size());
  for (double x : v)
    if (!std::isfinite(x)) throw InputError("", what, "holds NaN or infinite values");
  return v;
}

// (nm, values) or {"nm": [...], "W_per_sr_nm" | "values": [...]} as a table.
TabulatedSpectrum spectrum_from(const py::object& s, const std::string& what, Outside outside) {
  std::vector<double> nm, v;
  const char* forms = "expected {\"nm\": [...], \"W_per_sr_nm\": [...]} or (nm, values)";
  if (py::isinstance<py::dict>(s)) {
    py::dict d = s.cast<py::dict>();
    if (!d.contains("nm") || !(d.contains("W_per_sr_nm") || d.contains("values"))) throw InputError("", what, forms);
    nm = number_list(d["nm"], what + "/nm");
    v = number_list(d.contains("W_per_sr_nm") ? d["W_per_sr_nm"] : d["values"], what + "/values");
  } else {
    py::list t = items_of(s, what, "(nm, values) or {\"nm\": [...], \"values\": [...]}");
    if (t.size() != 2) throw InputError("", what, forms);
    nm = number_list(t[0], what + "/nm");
    v = number_list(t[1], what + "/values");
  }
  if (nm.size() != v.size() || nm.size() < 2) throw InputError("", what, "needs as many values as wavelengths, at least two");
  for (size_t i = 0; i < nm.size(); ++i) {
    if (i > 0 && !(nm[i] > nm[i - 1])) throw InputError("", what, "wavelengths must increase");
    if (!(v[i] >= 0)) throw InputError("", what, "values must be >= 0");
  }
  TabulatedSpectrum t;
  t.nm = nm;
  t.value = v;
  t.outside = outside;
  return t;
}

// (x, y, w, h): four integers, x, y >= 0 and w, h >= 1, inside a rows x cols image.
Roi roi_arg(const py::object& obj, int rows, int cols) {
  if (obj.is_none()) return {0, 0, cols, rows};
  py::list seq = items_of(obj, "roi", "(x, y, w, h) in pixels");
  if (py::len(seq) != 4) throw InputError("", "roi", "expected four integers (x, y, w, h), got " + std::to_string(py::len(seq)) + " values");
  Roi r;
  r.x = int(int_arg(seq[0], "roi", 0, cols - 1));
  r.y = int(int_arg(seq[1], "roi", 0, rows - 1));
  r.w = int(int_arg(seq[2], "roi", 1, cols - r.x));
  r.h = int(int_arg(seq[3], "roi", 1, rows - r.y));
  return r;
}

py::dict chromaticity(const py::object& raw_in, const py::object& cfa_in, const py::object& black_in, const py::object& white_in,
                      const py::object& roi_in, const py::object& mask_in, const py::object& include_saturated_in) {
  auto raw = py::array_t<uint16_t, py::array::c_style | py::array::forcecast>::ensure(raw_in);
  if (!raw || raw.ndim() != 2 || raw.shape(0) < 2 || raw.shape(1) < 2)
    throw InputError("", "raw", "expected a mosaic of shape (rows, cols), at least 2 x 2");
  int h = int(raw.shape(0)), w = int(raw.shape(1));
  if (!py::isinstance<py::str>(cfa_in)) throw InputError("", "cfa", "expected a CFA name such as \"RGGB\", got " + type_name(cfa_in));
  std::string cfa = cfa_in.cast<std::string>();
  auto p = parse_cfa_name(cfa);
  if (!p) throw InputError("", "cfa", "unknown CFA pattern \"" + printable(cfa) + "\" (expected RGGB, GRBG, GBRG or BGGR)");
  const double black = float_arg(black_in, "black", 0, 65535), white = float_arg(white_in, "white", 0, 65535);
  if (!(white > black)) throw InputError("", "white", "must be above black");
  Roi roi = roi_arg(roi_in, h, w);
  bool include_saturated = opt_bool_arg(include_saturated_in, "include_saturated").value_or(false);
  std::vector<uint16_t> dn(raw.data(), raw.data() + raw.size());
  std::vector<uint8_t> mask;
  if (!mask_in.is_none()) {
    auto m = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(mask_in);
    if (!m || m.ndim() != 2 || m.shape(0) != h || m.shape(1) != w)
      throw InputError("", "mask", "expected an array of the raw mosaic's shape (" + std::to_string(h) + ", " + std::to_string(w) + ")");
    mask.assign(m.data(), m.data() + m.size());
  }
  ChromaStats s;
  try {
    s = roi_chromaticity(dn, w, h, *p, black, white, roi, include_saturated, mask.empty() ? nullptr : &mask);
  } catch (const InputError& e) {
    if (e.field() != "--roi") throw;
    throw InputError(e.file(), "roi", e.what());  // the argument's name, not the CLI's option
  }
  py::dict d = from_json(s.to_json(false)).cast<py::dict>();
  py::array_t<double> rg({py::ssize_t(s.rg.size()), py::ssize_t(2)});
  for (size_t i = 0; i < s.rg.size(); ++i) {
    rg.mutable_at(i, 0) = s.rg[i][0];
    rg.mutable_at(i, 1) = s.rg[i][1];
  }
  d["rg"] = rg;
  return d;
}

std::vector<std::string> name_list(const py::object& obj, const std::string& what) {
  std::vector<std::string> out;
  for (auto x : items_of(obj, what, "a list of names")) {
    if (!py::isinstance<py::str>(x)) throw InputError("", what, "expected names (str), got " + type_name(x));
    out.push_back(x.cast<std::string>());
  }
  return out;
}

py::dict reference_lines(const CameraDescription& cam, const py::object& led, const py::object& reflectance,
                         const py::object& fluorophores_in, const py::object& concentrations_in, const py::object& grid_step_in,
                         const py::object& camera_range_in, const py::object& field_angle_in, const py::object& sensor_angle_in) {
  std::optional<std::vector<std::string>> fluorophores;
  if (!fluorophores_in.is_none()) fluorophores = name_list(fluorophores_in, "fluorophores");
  std::vector<double> concentrations = number_list(concentrations_in, "concentrations");
  for (double c : concentrations)
    if (c < 0) throw InputError("", "concentrations", "values must be >= 0");
  const double grid_step = float_arg(grid_step_in, "grid_step", 0.01, 50);
  std::optional<std::pair<double, double>> camera_range;
  if (!camera_range_in.is_none()) {
    std::vector<double> r = number_list(camera_range_in, "camera_range");
    if (r.size() != 2 || !(r[1] > r[0]) || !(r[0] > 0)) throw InputError("", "camera_range", "expected (lo_nm, hi_nm) with 0 < lo < hi");
    camera_range = std::pair{r[0], r[1]};
  }
  const double field_angle_deg = float_arg(field_angle_in, "field_angle_deg", 0, 89.9);
  std::optional<double> sensor_angle_deg;
  if (!sensor_angle_in.is_none()) sensor_angle_deg = float_arg(sensor_angle_in, "sensor_angle_deg", 0, 89.9);
  Spectrum led_s = table_spectrum(spectrum_from(led, "led", Outside::kZero), "LED");
  Spectrum refl = reflectance.is_none() ? tongue_reflectance_spectrum()
                                        : table_spectrum(spectrum_from(reflectance, "reflectance", Outside::kClamp), "reflectance");
  ReferenceOptions ro;
  ro.step_nm = grid_step;
  if (camera_range) {
    ro.camera_lo_nm = camera_range->first;
    ro.camera_hi_nm = camera_range->second;
  }
  ro.aoi_front_rad = field_angle_deg * kPi / 180.0;
  ro.aoi_sensor_rad = sensor_angle_deg.value_or(field_angle_deg) * kPi / 180.0;
  std::vector<std::string> names = fluorophores.value_or(std::vector<std::string>{});
  if (!fluorophores)
    for (auto& e : fluorophore_library()) names.push_back(e.name);
  nlohmann::json lines = nlohmann::json::array();
  nlohmann::json tongue;
  {
    py::gil_scoped_release release;
    ReferenceSetup setup = make_reference_setup(cam, led_s, refl, ro);
    tongue = reference_rg(setup, nullptr, 0.0);
    for (auto& n : names) {
      GridEem eem = load_fluorophore(n, setup.grid, std::filesystem::current_path());
      lines.push_back(reference_line(setup, n, eem, concentrations).to_json());
    }
  }
  py::dict d;
  d["lines"] = from_json(lines);
  d["tongue_rg"] = from_json(tongue);
  return d;
}

// (min, max, step) nm.
WavelengthGrid grid_arg(const py::object& obj) {
  py::list seq = items_of(obj, "grid", "(min_nm, max_nm, step_nm)");
  if (py::len(seq) != 3) throw InputError("", "grid", "expected three numbers (min_nm, max_nm, step_nm)");
  return WavelengthGrid{float_arg(seq[0], "grid", 1, 1e5), float_arg(seq[1], "grid", 1, 1e5), float_arg(seq[2], "grid", 1e-3, 1e5)};
}

py::list fluorophores(const py::object& grid) {
  WavelengthGrid g = grid_arg(grid);
  if (auto p = g.problem(); !p.empty()) throw InputError("", "grid", p);
  py::list out;
  for (auto& e : fluorophore_library()) {
    EemPeaks p = find_peaks(load_fluorophore(e.sidecar.string(), g));
    py::dict d;
    d["name"] = e.name;
    d["description"] = e.description;
    d["citation"] = e.citation;
    d["file"] = e.sidecar.string();
    d["peak_excitation_nm"] = p.excitation_nm;
    d["peak_emission_nm"] = p.emission_nm;
    out.append(d);
  }
  return out;
}

py::dict fluorophore_eem(const py::object& name_in, const py::object& grid) {
  if (!py::isinstance<py::str>(name_in)) throw InputError("", "name", "expected a fluorophore name, got " + type_name(name_in));
  const std::string name = name_in.cast<std::string>();
  WavelengthGrid g = grid_arg(grid);
  if (auto p = g.problem(); !p.empty()) throw InputError("", "grid", p);
  GridEem e = load_fluorophore(name, g, std::filesystem::current_path());
  const int n = e.n();
  py::array_t<double> m({n, n});
  std::copy(e.m.begin(), e.m.end(), m.mutable_data());
  std::vector<double> nm;
  for (int i = 0; i < n; ++i) nm.push_back(g.wavelength(i));
  EemPeaks p = find_peaks(e);
  py::dict d;
  d["name"] = name;
  d["eem"] = m;
  d["emission_nm"] = py::array_t<double>(nm.size(), nm.data());
  d["excitation_nm"] = py::array_t<double>(nm.size(), nm.data());
  auto alb = e.photon_albedo();
  d["photon_albedo"] = py::array_t<double>(alb.size(), alb.data());
  d["peak_excitation_nm"] = p.excitation_nm;
  d["peak_emission_nm"] = p.emission_nm;
  return d;
}

}  // namespace

void bind_analysis(py::module_& m) {
  m.def("chromaticity", &chromaticity, py::arg("raw"), py::arg("cfa"), py::arg("black"), py::arg("white"),
        py::arg("roi") = py::none(), py::arg("mask") = py::none(), py::arg("include_saturated") = false,
        "r, g per 2x2 CFA cell of a raw mosaic in roi (x, y, w, h): mean, covariance, 95 % ellipse, and rg per cell");
  m.def("_reference_lines", &reference_lines, py::arg("camera"), py::arg("led"), py::arg("reflectance") = py::none(),
        py::arg("fluorophores") = py::none(), py::arg("concentrations") = py::list(), py::arg("grid_step") = 1.0,
        py::arg("camera_range") = py::none(), py::arg("field_angle_deg") = 0.0, py::arg("sensor_angle_deg") = py::none());
  m.def("fluorophores", &fluorophores, py::arg("grid") = py::make_tuple(350, 830, 5),
        "the shipped fluorophore library: name, description, citation, file, peak excitation and emission");
  m.def("fluorophore_eem", &fluorophore_eem, py::arg("name"), py::arg("grid") = py::make_tuple(350, 830, 5),
        "a fluorophore's EEM on a grid (min, max, step nm): eem[emission, excitation] in photons per nm per photon, "
        "with emission_nm, excitation_nm and photon_albedo");
}

}  // namespace ofl::python
