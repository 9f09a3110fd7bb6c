// The compiled part of the `oralfluor` Python package (python/oralfluor/ wraps it). It exposes the
// jobs of the CLI on numpy arrays: scenes, render, spectral EXR, camera, chromaticity, fluorophore
// library, diagnose, ISETCam .mat exchange. See docs/python.md.
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "python/src/common.h"
#include "renderer/core/error.h"

namespace ofl::python {

nlohmann::json to_json(const py::handle& obj, const std::string& what) {
  py::object dumps = py::module_::import("json").attr("dumps");
  std::string text;
  try {
    text = dumps(obj, py::arg("allow_nan") = false).cast<std::string>();
  } catch (py::error_already_set& e) {
    throw InputError(what, "", std::string("cannot be written as JSON: ") + e.what());
  }
  return nlohmann::json::parse(text);
}

py::object from_json(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

py::array_t<float> cube(const std::vector<float>& data, int height, int width, int bands) {
  py::array_t<float> a({height, width, bands});
  if (data.size() != size_t(height) * width * bands) throw std::logic_error("cube: size mismatch");
  std::copy(data.begin(), data.end(), a.mutable_data());
  return a;
}

py::array_t<float> plane(const std::vector<float>& data, int height, int width) {
  py::array_t<float> a({height, width});
  if (data.size() != size_t(height) * width) throw std::logic_error("plane: size mismatch");
  std::copy(data.begin(), data.end(), a.mutable_data());
  return a;
}

void run_without_gil(int threads, const std::function<void()>& f) {
  py::gil_scoped_release release;
  if (threads > 0) {
    tbb::task_arena arena(threads);
    arena.execute(f);
  } else {
    f();
  }
}

}  // namespace ofl::python

PYBIND11_MODULE(_oralfluor, m) {
  using namespace ofl::python;
  m.doc() = "oralfluor: spectral path tracer and camera simulator for oral fluorescence imaging (compiled core)";
  static py::exception<ofl::InputError> input_error(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ofl::InputError& e) {
      // The message is the CLI's one line (without "error: "); file and field are attributes too.
      py::object inst = py::handle(input_error.ptr())(py::str(e.describe()));  // an instance of the class
      inst.attr("file") = py::str(e.file());
      inst.attr("field") = py::str(e.field());
      inst.attr("reason") = py::str(e.what());
      PyErr_SetObject(input_error.ptr(), inst.ptr());
    } catch (const ofl::Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });
  bind_image(m);
  bind_render(m);
  bind_camera(m);
  bind_analysis(m);
  bind_interop(m);
}
