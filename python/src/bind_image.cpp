// SpectralImage <-> numpy, and the spectral EXR reader and writer. The arrays an image hands out are
// read-only views of its own memory (no copy per access; writing raises rather than silently
// editing a rendered result), kept alive by the image object.
#include <cmath>

#include "python/src/common.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"

namespace ofl::python {
namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;


// A numeric array of `ndim` dimensions as float32 (C order), or InputError naming `name`.
FloatArray float_array(const py::handle& obj, int ndim, const std::string& name, const char* shape) {
  FloatArray a = FloatArray::ensure(obj);
  if (!a || py::isinstance<py::str>(obj)) throw InputError("", name, std::string("expected a numeric array of shape ") + shape + ", got " + type_name(obj));
  if (a.ndim() != ndim)
    throw InputError("", name, std::string("expected an array of shape ") + shape + ", got " + std::to_string(a.ndim()) + " dimensions");
  for (py::ssize_t i = 0; i < a.size(); ++i)
    if (!std::isfinite(a.data()[i])) throw InputError("", name, "holds NaN or infinite values");
  return a;
}

std::vector<double> wavelength_list(const py::handle& obj, size_t bands) {
  auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || py::isinstance<py::str>(obj) || a.ndim() != 1)
    throw InputError("", "wavelengths", "expected a list or 1-D array of band centres in nm");
  std::vector<double> nm(a.data(), a.data() + a.size());
  if (nm.size() != bands)
    throw InputError("", "wavelengths", "has " + std::to_string(nm.size()) + " values for " + std::to_string(bands) + " bands");
  for (size_t i = 0; i < nm.size(); ++i) {
    if (!(nm[i] > 0) || !std::isfinite(nm[i])) throw InputError("", "wavelengths", "values must be finite and > 0 nm");
    if (i > 0 && !(nm[i] > nm[i - 1])) throw InputError("", "wavelengths", "must increase");
  }
  return nm;
}

SpectralImage make_image(const py::object& radiance, const py::object& wavelengths, const py::object& fluorescence,
                         const py::object& aovs, const py::object& attributes) {
  SpectralImage img;
  FloatArray r = float_array(radiance, 3, "radiance", "(rows, cols, bands)");
  const int h = int(r.shape(0)), w = int(r.shape(1)), b = int(r.shape(2));
  if (h < 1 || w < 1 || b < 1) throw InputError("", "radiance", "is empty (shape needs rows, cols, bands >= 1)");
  img.data.assign(r.data(), r.data() + r.size());
  img.band_nm = wavelength_list(wavelengths, size_t(b));
  img.width = w;
  img.height = h;
  if (!fluorescence.is_none()) {
    FloatArray f = float_array(fluorescence, 3, "fluorescence", "(rows, cols, bands)");
    if (f.shape(0) != h || f.shape(1) != w || f.shape(2) != b) throw InputError("", "fluorescence", "must have the shape of radiance");
    img.fluorescence.assign(f.data(), f.data() + f.size());
  }
  if (!aovs.is_none()) {
    if (!py::isinstance<py::dict>(aovs)) throw InputError("", "aovs", "expected a dict {name: array (rows, cols)}");
    for (auto& [k, v] : aovs.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k)) throw InputError("", "aovs", "keys must be str");
      std::string name = k.cast<std::string>();
      FloatArray a = float_array(v, 2, "aovs/" + name, "(rows, cols)");
      if (a.shape(0) != h || a.shape(1) != w) throw InputError("", "aovs/" + name, "expected an array of shape (rows, cols) of radiance");
      img.aovs[name.rfind("aov.", 0) == 0 ? name : "aov." + name] = std::vector<float>(a.data(), a.data() + a.size());
    }
  }
  if (!attributes.is_none()) {
    if (!py::isinstance<py::dict>(attributes)) throw InputError("", "attributes", "expected a dict {str: str}");
    for (auto& [k, v] : attributes.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k) || !py::isinstance<py::str>(v)) throw InputError("", "attributes", "keys and values must be str");
      img.attributes[k.cast<std::string>()] = v.cast<std::string>();
    }
  }
  return img;
}

py::array band_array(const std::vector<double>& v) { return py::array_t<double>(py::ssize_t(v.size()), v.data()); }

}  // namespace

const SpectralImage& image_arg(const py::handle& obj, const std::string& arg) {
  py::handle h = obj;
  py::object inner;
  if (!py::isinstance<SpectralImage>(h) && py::hasattr(h, "image")) {  // a RenderResult
    inner = h.attr("image");
    h = inner;
  }
  if (!py::isinstance<SpectralImage>(h))
    throw InputError("", arg, "expected a SpectralImage (or a RenderResult), got " + type_name(obj));
  return h.cast<const SpectralImage&>();
}

void bind_image(py::module_& m) {
  py::class_<SpectralImage>(m, "SpectralImage",
                            "Spectral radiance image: radiance (rows, cols, bands) in W sr^-1 m^-2 nm^-1 on the band "
                            "centres `wavelengths`, optional fluorescence layer and per-pixel AOV planes, header attributes.")
      .def(py::init(&make_image), py::arg("radiance"), py::arg("wavelengths"), py::arg("fluorescence") = py::none(),
           py::arg("aovs") = py::none(), py::arg("attributes") = py::none())
      .def_property_readonly("radiance", [](py::object self) {
             const auto& i = self.cast<const SpectralImage&>();
             return view(i.data, {i.height, i.width, i.bands()}, self);
           }, "float32 array (rows, cols, bands), W sr^-1 m^-2 nm^-1 (a read-only view; .copy() to edit)")
      .def_property_readonly("wavelengths", [](const SpectralImage& i) { return band_array(i.band_nm); }, "band centres in nm")
      .def_property_readonly("band_lo", [](const SpectralImage& i) { return band_array(i.band_lo()); }, "lower band edges in nm")
      .def_property_readonly("band_hi", [](const SpectralImage& i) { return band_array(i.band_hi()); }, "upper band edges in nm")
      .def_property_readonly("fluorescence", [](py::object self) -> py::object {
             const auto& i = self.cast<const SpectralImage&>();
             if (i.fluorescence.empty()) return py::none();
             return view(i.fluorescence, {i.height, i.width, i.bands()}, self);
           }, "the fluorescent part of the radiance (same shape, read-only view), or None")
      .def_property_readonly("aovs", [](py::object self) {
             const auto& i = self.cast<const SpectralImage&>();
             py::dict d;
             for (auto& [k, v] : i.aovs) d[py::str(k.rfind("aov.", 0) == 0 ? k.substr(4) : k)] = view(v, {i.height, i.width}, self);
             return d;
           }, "per-pixel planes (read-only views): material (index into the scene's materials, -1 none, -2 LED), u, v, "
              "depth, cos_view, irradiance")
      .def_property_readonly("attributes", [](const SpectralImage& i) {
             py::dict d;
             for (auto& [k, v] : i.attributes) d[text(k)] = text(v);
             return d;
           }, "header strings (bytes that are not UTF-8 shown as U+FFFD)")
      .def_property_readonly("width", [](const SpectralImage& i) { return i.width; })
      .def_property_readonly("height", [](const SpectralImage& i) { return i.height; })
      .def_property_readonly("shape", [](const SpectralImage& i) { return py::make_tuple(i.height, i.width, i.bands()); })
      .def("srgb", [](const SpectralImage& i, const py::object& white) {
             double w;
             try {
               w = white.cast<double>();
             } catch (const py::cast_error&) {
               throw InputError("", "white_radiance", "expected a number, got " + type_name(white));
             }
             if (!(w > 0) || !std::isfinite(w)) throw InputError("", "white_radiance", "must be a finite number > 0");
             auto v = spectral_to_linear_srgb(i, w);
             return cube(v, i.height, i.width, 3);
           }, py::arg("white_radiance") = 1.0, "linear sRGB (rows, cols, 3) through CIE 1931, Y = 1 for a flat radiance of white_radiance")
      .def("__repr__", [](const SpectralImage& i) {
        return "<oralfluor.SpectralImage " + std::to_string(i.height) + "x" + std::to_string(i.width) + ", " +
               std::to_string(i.bands()) + " bands" + (i.bands() ? " " + std::to_string(i.band_nm.front()) + "-" + std::to_string(i.band_nm.back()) + " nm" : "") + ">";
      });
  m.def("read_exr", [](const py::object& path) { return read_spectral_exr(path_arg(path, "path")); }, py::arg("path"),
        "read a spectral EXR (every S0 channel, the fluorescence layer, aov.* planes, header strings)");
  m.def("write_exr", [](const py::object& path, const py::object& image) {
          write_spectral_exr(path_arg(path, "path"), image_arg(image, "image"));
        }, py::arg("path"), py::arg("image"), "write a spectral EXR (an image or a render result) in the layout oralfluor render writes");
}

}  // namespace ofl::python
