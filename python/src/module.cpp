// The compiled part of the `oralfluor` Python package (python/oralfluor/ wraps it). It exposes the
// jobs of the CLI on numpy arrays: scenes, render, spectral EXR, camera, chromaticity, fluorophore
// library, diagnose, ISETCam .mat exchange. See docs/python.md.
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <sstream>

#include "python/src/common.h"
#include "renderer/core/errors/error.h"

namespace ofl::python {

namespace {
// json.dumps' `default`: numpy scalars and arrays (anything with tolist/item) and paths.
py::object json_default(const py::handle& o) {
  if (py::hasattr(o, "tolist")) return o.attr("tolist")();
  if (py::hasattr(o, "__fspath__")) return py::module_::import("os").attr("fspath")(o);
  throw py::type_error("a " + py::str(py::type::of(o).attr("__name__")).cast<std::string>() + " (" +
                       py::repr(o).cast<std::string>().substr(0, 60) + ")");
}
}  // namespace

nlohmann::json to_json(const py::handle& obj, const std::string& what) {
  py::object dumps = py::module_::import("json").attr("dumps");
  std::string text;
  try {
    text = dumps(obj, py::arg("allow_nan") = false, py::arg("default") = py::cpp_function(&json_default)).cast<std::string>();
  } catch (py::error_already_set& e) {
    // The exception's own text, without the traceback pybind11 would embed.
    throw InputError(what, "", "cannot be written as JSON: " + py::str(e.value()).cast<std::string>());
  }
  return nlohmann::json::parse(text);
}

std::string type_name(const py::handle& o) { return py::str(py::type::of(o).attr("__name__")).cast<std::string>(); }

namespace {
std::string range_text(int64_t lo, int64_t hi) { return "not in range " + std::to_string(lo) + " to " + std::to_string(hi); }

// operator.index(obj) (int and numpy integers; bool refused: True is not a sample count), or InputError.
py::int_ index_of(const py::handle& obj, const std::string& arg, const std::string& expected) {
  PyObject* i = nullptr;
  if (!py::isinstance<py::bool_>(obj) && type_name(obj) != "bool_" && PyIndex_Check(obj.ptr())) i = PyNumber_Index(obj.ptr());
  if (!i) {  // not an integer (a numpy array has __index__ but refuses it: that error is ours to give)
    PyErr_Clear();
    std::string shown = py::isinstance<py::array>(obj) ? "an array" : py::repr(obj).cast<std::string>().substr(0, 40);
    throw InputError("", arg, "expected " + expected + ", got " + type_name(obj) + " " + shown);
  }
  return py::reinterpret_steal<py::int_>(i);
}
}  // namespace

int64_t int_arg(const py::handle& obj, const std::string& arg, int64_t lo, int64_t hi) {
  py::int_ i = index_of(obj, arg, "an integer " + range_text(lo, hi).substr(4));
  int overflow = 0;
  long long v = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow != 0 || v < lo || v > hi)
    throw InputError("", arg, "value " + py::str(i).cast<std::string>() + " " + range_text(lo, hi));
  return v;
}

std::optional<int64_t> opt_int_arg(const py::handle& obj, const std::string& arg, int64_t lo, int64_t hi) {
  if (obj.is_none()) return std::nullopt;
  return int_arg(obj, arg, lo, hi);
}

std::optional<uint64_t> seed_arg(const py::handle& obj, const std::string& arg) {
  if (obj.is_none()) return std::nullopt;
  py::int_ i = index_of(obj, arg, "an integer in range 0 to 18446744073709551615");
  unsigned long long v = 0;
  if (PyObject_RichCompareBool(i.ptr(), py::int_(0).ptr(), Py_LT) == 1 ||
      (v = PyLong_AsUnsignedLongLong(i.ptr()), PyErr_Occurred())) {
    PyErr_Clear();
    throw InputError("", arg, "value " + py::str(i).cast<std::string>() + " not in range 0 to 18446744073709551615");
  }
  return uint64_t(v);
}

int threads_arg(const py::handle& obj) { return obj.is_none() ? 0 : int(int_arg(obj, "threads", 0, 1024)); }

double float_arg(const py::handle& obj, const std::string& arg, double lo, double hi) {
  if (py::isinstance<py::bool_>(obj) || py::isinstance<py::str>(obj) || !PyNumber_Check(obj.ptr()) ||
      type_name(obj) == "bool_")
    throw InputError("", arg, "expected a number, got " + type_name(obj));
  double v = PyFloat_AsDouble(obj.ptr());
  if (PyErr_Occurred()) {
    PyErr_Clear();
    throw InputError("", arg, "expected a real number, got " + type_name(obj));
  }
  if (!std::isfinite(v) || v < lo || v > hi) {
    std::ostringstream s;
    s << "value " << v << " not in range " << lo << " to " << hi;
    throw InputError("", arg, s.str());
  }
  return v;
}

std::optional<bool> opt_bool_arg(const py::handle& obj, const std::string& arg) {
  if (obj.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(obj) || type_name(obj) == "bool_") return PyObject_IsTrue(obj.ptr()) == 1;
  throw InputError("", arg, "expected True or False, got " + type_name(obj));
}

std::string path_arg(const py::handle& obj, const std::string& arg) {
  if (py::isinstance<py::str>(obj)) return obj.cast<std::string>();
  if (py::hasattr(obj, "__fspath__")) {
    py::object p = py::module_::import("os").attr("fspath")(obj);
    if (py::isinstance<py::str>(p)) return p.cast<std::string>();
  }
  throw InputError("", arg, "expected a file name (str or pathlib.Path), got " +
                                py::str(py::type::of(obj).attr("__name__")).cast<std::string>());
}

py::object from_json(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

py::str text(const std::string& s) {
  return py::reinterpret_steal<py::str>(PyUnicode_DecodeUTF8(s.data(), py::ssize_t(s.size()), "replace"));
}

py::list items_of(const py::handle& obj, const std::string& what, const std::string& expected) {
  py::object o = py::isinstance<py::array>(obj) ? obj.attr("tolist")() : py::reinterpret_borrow<py::object>(obj);
  if (py::isinstance<py::str>(o) || py::isinstance<py::bytes>(o) || !py::isinstance<py::sequence>(o))
    throw InputError("", what, "expected " + expected + ", got " + type_name(obj));
  return py::list(o);
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
