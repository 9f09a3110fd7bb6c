// Shared helpers of the oralfluor Python module: JSON <-> Python objects, numpy arrays, the GIL and
// thread count around long calls.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/camera_description.h"
#include "renderer/image/spectral_image.h"

namespace py = pybind11;

namespace ofl::python {

// Python object (dict, list, numbers, strings) -> JSON, through Python's json module so that the
// conversion rules are Python's own; numpy scalars and arrays become numbers and lists, paths
// strings. NaN/inf are refused (JSON has no such numbers). InputError names `what`.
nlohmann::json to_json(const py::handle& obj, const std::string& what);
// JSON -> Python objects (bytes that are not UTF-8 become U+FFFD).
py::object from_json(const nlohmann::json& j);
// Text read from a file -> str, bytes that are not UTF-8 becoming U+FFFD (never UnicodeDecodeError).
py::str text(const std::string& s);
// A list, tuple or 1-D array as a Python list, else InputError naming `what` (str, bytes, numbers and
// 0-d arrays included): "expected <expected>, got <type>".
py::list items_of(const py::handle& obj, const std::string& what, const std::string& expected);

// float32 array (rows, cols, bands) copied from a SpectralImage layout (row-major, bands contiguous).
py::array_t<float> cube(const std::vector<float>& data, int height, int width, int bands);
py::array_t<float> plane(const std::vector<float>& data, int height, int width);

// A read-only numpy view of `data` (C order, `shape`) that keeps `owner` (the Python object holding
// the vector) alive: no copy per access, and writing raises instead of silently editing a result.
template <typename T>
py::array view(const std::vector<T>& data, std::vector<py::ssize_t> shape, const py::handle& owner) {
  py::array_t<T> a(shape, data.data(), owner);
  a.attr("setflags")(py::arg("write") = false);
  return std::move(a);
}

// A SpectralImage, or the image of a RenderResult (anything with a SpectralImage `.image`), else
// InputError naming `arg`. The reference lives as long as `obj`.
const SpectralImage& image_arg(const py::handle& obj, const std::string& arg);

// Arguments checked as the CLI checks its options, raising InputError naming the argument: an
// integer (Python int or numpy integer; not bool, float or str) in [lo, hi]; None gives nullopt.
int64_t int_arg(const py::handle& obj, const std::string& arg, int64_t lo, int64_t hi);
std::optional<int64_t> opt_int_arg(const py::handle& obj, const std::string& arg, int64_t lo, int64_t hi);
// A seed: an integer in [0, 2^64 - 1], or None.
std::optional<uint64_t> seed_arg(const py::handle& obj, const std::string& arg);
// Worker threads: None or 0 (all cores) up to 1024, as the CLI's --threads.
int threads_arg(const py::handle& obj);
// A real number (int, float, numpy scalar; not bool or str), finite, in [lo, hi].
double float_arg(const py::handle& obj, const std::string& arg, double lo, double hi);
// A truth value: bool or numpy bool (None gives nullopt).
std::optional<bool> opt_bool_arg(const py::handle& obj, const std::string& arg);
// The name of the argument's type, for messages.
std::string type_name(const py::handle& obj);

// A Camera, a camera.json / ISETCam sensor .mat path (str or pathlib.Path), or a camera dict, else
// InputError naming "camera".
CameraDescription camera_arg(const py::object& src);

// A file-name argument: str or os.PathLike (pathlib.Path), else InputError naming `arg`.
std::string path_arg(const py::handle& obj, const std::string& arg);

// Runs `f` with the GIL released, on `threads` worker threads (0: all cores) in a TBB arena.
void run_without_gil(int threads, const std::function<void()>& f);

void bind_image(py::module_& m);
void bind_render(py::module_& m);
void bind_camera(py::module_& m);
void bind_analysis(py::module_& m);
void bind_interop(py::module_& m);

}  // namespace ofl::python
