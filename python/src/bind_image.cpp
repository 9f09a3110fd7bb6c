// SpectralImage <-> numpy, and the spectral EXR reader and writer.
#include "python/src/common.h"
#include "renderer/core/error.h"
#include "renderer/image/spectral_exr.h"

namespace ofl::python {
namespace {

std::vector<float> from_cube(const py::array_t<float, py::array::c_style | py::array::forcecast>& a, int* h, int* w,
                             int* b, const char* name) {
  if (a.ndim() != 3) throw InputError("", name, "expected an array of shape (rows, cols, bands)");
  *h = int(a.shape(0));
  *w = int(a.shape(1));
  *b = int(a.shape(2));
  return std::vector<float>(a.data(), a.data() + a.size());
}

SpectralImage make_image(const py::array_t<float, py::array::c_style | py::array::forcecast>& radiance,
                         const std::vector<double>& wavelengths, const std::optional<py::array>& fluorescence,
                         const std::optional<py::dict>& aovs, const std::optional<std::map<std::string, std::string>>& attributes) {
  SpectralImage img;
  int h, w, b;
  img.data = from_cube(radiance, &h, &w, &b, "radiance");
  if (size_t(b) != wavelengths.size())
    throw InputError("", "wavelengths", "has " + std::to_string(wavelengths.size()) + " values for " + std::to_string(b) + " bands");
  for (size_t i = 1; i < wavelengths.size(); ++i)
    if (!(wavelengths[i] > wavelengths[i - 1])) throw InputError("", "wavelengths", "must increase");
  img.width = w;
  img.height = h;
  img.band_nm = wavelengths;
  if (fluorescence && !fluorescence->is_none()) {
    int h2, w2, b2;
    img.fluorescence = from_cube(*fluorescence, &h2, &w2, &b2, "fluorescence");
    if (h2 != h || w2 != w || b2 != b) throw InputError("", "fluorescence", "must have the shape of radiance");
  }
  if (aovs)
    for (auto& [k, v] : *aovs) {
      auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(v);
      std::string name = k.cast<std::string>();
      if (!a || a.ndim() != 2 || a.shape(0) != h || a.shape(1) != w) throw InputError("", "aovs/" + name, "expected an array of shape (rows, cols)");
      img.aovs[name.rfind("aov.", 0) == 0 ? name : "aov." + name] = std::vector<float>(a.data(), a.data() + a.size());
    }
  if (attributes) img.attributes = *attributes;
  return img;
}

}  // namespace

void bind_image(py::module_& m) {
  py::class_<SpectralImage>(m, "SpectralImage",
                            "Spectral radiance image: radiance (rows, cols, bands) in W sr^-1 m^-2 nm^-1 on the band "
                            "centres `wavelengths`, optional fluorescence layer and per-pixel AOV planes, header attributes.")
      .def(py::init(&make_image), py::arg("radiance"), py::arg("wavelengths"), py::arg("fluorescence") = py::none(),
           py::arg("aovs") = py::none(), py::arg("attributes") = py::none())
      .def_property_readonly("radiance", [](const SpectralImage& i) { return cube(i.data, i.height, i.width, i.bands()); },
                             "float32 array (rows, cols, bands), W sr^-1 m^-2 nm^-1 (a copy)")
      .def_property_readonly("wavelengths", [](const SpectralImage& i) { return py::array_t<double>(i.band_nm.size(), i.band_nm.data()); },
                             "band centres in nm")
      .def_property_readonly("band_lo", [](const SpectralImage& i) { auto v = i.band_lo(); return py::array_t<double>(v.size(), v.data()); })
      .def_property_readonly("band_hi", [](const SpectralImage& i) { auto v = i.band_hi(); return py::array_t<double>(v.size(), v.data()); })
      .def_property_readonly("fluorescence",
                             [](const SpectralImage& i) -> py::object {
                               if (i.fluorescence.empty()) return py::none();
                               return cube(i.fluorescence, i.height, i.width, i.bands());
                             },
                             "the fluorescent part of the radiance (same shape), or None")
      .def_property_readonly("aovs",
                             [](const SpectralImage& i) {
                               py::dict d;
                               for (auto& [k, v] : i.aovs) d[py::str(k.rfind("aov.", 0) == 0 ? k.substr(4) : k)] = plane(v, i.height, i.width);
                               return d;
                             },
                             "per-pixel planes: material (index into the scene's materials, -1 none, -2 LED), u, v, depth, "
                             "cos_view, irradiance")
      .def_property_readonly("attributes", [](const SpectralImage& i) { return i.attributes; }, "header strings")
      .def_property_readonly("width", [](const SpectralImage& i) { return i.width; })
      .def_property_readonly("height", [](const SpectralImage& i) { return i.height; })
      .def_property_readonly("shape", [](const SpectralImage& i) { return py::make_tuple(i.height, i.width, i.bands()); })
      .def("srgb", [](const SpectralImage& i, double white) {
             auto v = spectral_to_linear_srgb(i, white);
             return cube(v, i.height, i.width, 3);
           }, py::arg("white_radiance") = 1.0, "linear sRGB (rows, cols, 3) through CIE 1931, Y = 1 for a flat radiance of white_radiance")
      .def("__repr__", [](const SpectralImage& i) {
        return "<oralfluor.SpectralImage " + std::to_string(i.height) + "x" + std::to_string(i.width) + ", " +
               std::to_string(i.bands()) + " bands" + (i.bands() ? " " + std::to_string(i.band_nm.front()) + "-" + std::to_string(i.band_nm.back()) + " nm" : "") + ">";
      });
  m.def("read_exr", [](const std::string& path) { return read_spectral_exr(path); }, py::arg("path"),
        "read a spectral EXR (every S0 channel, the fluorescence layer, aov.* planes, header strings)");
  m.def("write_exr", [](const std::string& path, const SpectralImage& img) { write_spectral_exr(path, img); },
        py::arg("path"), py::arg("image"), "write a spectral EXR in the layout oralfluor render writes");
}

}  // namespace ofl::python
