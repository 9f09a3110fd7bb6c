// Chromaticity of raw mosaics, the fluorophore reference lines (figure 5 of the OralEye paper) and
// the fluorophore library with its EEMs as arrays.
#include <filesystem>

#include "python/src/common.h"
#include "renderer/analysis/chroma_reference.h"
#include "renderer/analysis/chromaticity.h"
#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/core/error.h"
#include "renderer/spectral/fluorophore_library.h"
#include "renderer/spectral/units.h"

namespace ofl::python {
namespace {

// (nm, values) or {"nm": [...], "W_per_sr_nm" | "values": [...]} as a table.
TabulatedSpectrum spectrum_from(const py::object& s, const std::string& what, Outside outside) {
  std::vector<double> nm, v;
  if (py::isinstance<py::dict>(s)) {
    py::dict d = s.cast<py::dict>();
    if (!d.contains("nm")) throw InputError("", what, "expected {\"nm\": [...], \"W_per_sr_nm\": [...]} or (nm, values)");
    nm = d["nm"].cast<std::vector<double>>();
    v = (d.contains("W_per_sr_nm") ? d["W_per_sr_nm"] : d["values"]).cast<std::vector<double>>();
  } else {
    auto t = s.cast<py::tuple>();
    if (t.size() != 2) throw InputError("", what, "expected (nm, values)");
    nm = t[0].cast<std::vector<double>>();
    v = t[1].cast<std::vector<double>>();
  }
  if (nm.size() != v.size() || nm.size() < 2) throw InputError("", what, "needs as many values as wavelengths, at least two");
  for (size_t i = 0; i < nm.size(); ++i) {
    if (i > 0 && !(nm[i] > nm[i - 1])) throw InputError("", what, "wavelengths must increase");
    if (!(v[i] >= 0) || !std::isfinite(v[i])) throw InputError("", what, "values must be finite and >= 0");
  }
  TabulatedSpectrum t;
  t.nm = nm;
  t.value = v;
  t.outside = outside;
  return t;
}

py::dict chromaticity(const py::array_t<uint16_t, py::array::c_style | py::array::forcecast>& raw, const std::string& cfa,
                      double black, double white, std::optional<std::array<int, 4>> roi_in,
                      std::optional<py::array_t<uint8_t, py::array::c_style | py::array::forcecast>> mask_in,
                      bool include_saturated) {
  if (raw.ndim() != 2) throw InputError("", "raw", "expected a mosaic of shape (rows, cols)");
  int h = int(raw.shape(0)), w = int(raw.shape(1));
  auto p = parse_cfa_name(cfa);
  if (!p) throw InputError("", "cfa", "unknown CFA pattern \"" + cfa + "\" (expected RGGB, GRBG, GBRG or BGGR)");
  Roi roi{0, 0, w, h};
  if (roi_in) roi = {(*roi_in)[0], (*roi_in)[1], (*roi_in)[2], (*roi_in)[3]};
  std::vector<uint16_t> dn(raw.data(), raw.data() + raw.size());
  std::vector<uint8_t> mask;
  if (mask_in) {
    if (mask_in->ndim() != 2 || mask_in->shape(0) != h || mask_in->shape(1) != w)
      throw InputError("", "mask", "expected the raw mosaic's shape");
    mask.assign(mask_in->data(), mask_in->data() + mask_in->size());
  }
  ChromaStats s = roi_chromaticity(dn, w, h, *p, black, white, roi, include_saturated, mask.empty() ? nullptr : &mask);
  py::dict d = from_json(s.to_json(false)).cast<py::dict>();
  py::array_t<double> rg({py::ssize_t(s.rg.size()), py::ssize_t(2)});
  for (size_t i = 0; i < s.rg.size(); ++i) {
    rg.mutable_at(i, 0) = s.rg[i][0];
    rg.mutable_at(i, 1) = s.rg[i][1];
  }
  d["rg"] = rg;
  return d;
}

py::dict reference_lines(const CameraDescription& cam, const py::object& led, const py::object& reflectance,
                         std::optional<std::vector<std::string>> fluorophores, std::vector<double> concentrations,
                         double grid_step, std::optional<std::pair<double, double>> camera_range, double field_angle_deg,
                         std::optional<double> sensor_angle_deg) {
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

py::list fluorophores(std::array<double, 3> grid) {
  WavelengthGrid g{grid[0], grid[1], grid[2]};
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

py::dict fluorophore_eem(const std::string& name, std::array<double, 3> grid) {
  WavelengthGrid g{grid[0], grid[1], grid[2]};
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
        py::arg("fluorophores") = py::none(), py::arg("concentrations") = std::vector<double>{}, py::arg("grid_step") = 1.0,
        py::arg("camera_range") = py::none(), py::arg("field_angle_deg") = 0.0, py::arg("sensor_angle_deg") = py::none());
  m.def("fluorophores", &fluorophores, py::arg("grid") = std::array<double, 3>{350, 830, 5},
        "the shipped fluorophore library: name, description, citation, file, peak excitation and emission");
  m.def("fluorophore_eem", &fluorophore_eem, py::arg("name"), py::arg("grid") = std::array<double, 3>{350, 830, 5},
        "a fluorophore's EEM on a grid (min, max, step nm): eem[emission, excitation] in photons per nm per photon, "
        "with emission_nm, excitation_nm and photon_albedo");
}

}  // namespace ofl::python
