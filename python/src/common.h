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

#include "renderer/image/spectral_image.h"

namespace py = pybind11;

namespace ofl::python {

// Python object (dict, list, numbers, strings) -> JSON, through Python's json module so that the
// conversion rules are Python's own. NaN/inf are refused (JSON has no such numbers).
nlohmann::json to_json(const py::handle& obj, const std::string& what);
// JSON -> Python objects.
py::object from_json(const nlohmann::json& j);

// float32 array (rows, cols, bands) copied from a SpectralImage layout (row-major, bands contiguous).
py::array_t<float> cube(const std::vector<float>& data, int height, int width, int bands);
py::array_t<float> plane(const std::vector<float>& data, int height, int width);

// Runs `f` with the GIL released, on `threads` worker threads (0: all cores) in a TBB arena.
void run_without_gil(int threads, const std::function<void()>& f);

void bind_image(py::module_& m);
void bind_render(py::module_& m);
void bind_camera(py::module_& m);
void bind_analysis(py::module_& m);
void bind_interop(py::module_& m);

}  // namespace ofl::python
