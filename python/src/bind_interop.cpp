// MATLAB/ISETCam exchange (.mat through libmatio) and `oralfluor diagnose` as a call returning dicts.
#include <tbb/task_arena.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>

#include "python/src/common.h"
#include "renderer/core/errors/error.h"
#include "renderer/diagnose/diagnose_job.h"
#include "renderer/interop/iset_oi.h"
#include "renderer/interop/iset_scene.h"
#include "renderer/formats/iset_sensor.h"
#include "renderer/formats/mat_file.h"
#include "renderer/formats/mat_spectrum.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl::python {
namespace {

// Python value -> MatValue: dict -> struct, str -> char, list/tuple of str -> cell row,
// numpy array / number / list of numbers -> double (float32 arrays stay single).
MatValue to_mat(const py::handle& v, const std::string& where) {
  if (py::isinstance<py::dict>(v)) {
    MatValue s = MatValue::structure();
    for (auto& [k, x] : v.cast<py::dict>()) s.set(py::str(k).cast<std::string>(), to_mat(x, where + "." + py::str(k).cast<std::string>()));
    return s;
  }
  if (py::isinstance<py::str>(v)) return MatValue::string(v.cast<std::string>());
  if ((py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) && py::len(v) > 0 && py::isinstance<py::str>(v.cast<py::sequence>()[0])) {
    std::vector<MatValue> cells;
    for (auto x : v.cast<py::sequence>()) cells.push_back(to_mat(x, where));
    return MatValue::cell_row(std::move(cells));
  }
  py::array a = py::array::ensure(v);
  if (!a) throw InputError("", where, "cannot be written to a .mat file (expected a dict, str, list of str or numbers)");
  bool single = a.dtype().is(py::dtype::of<float>());
  auto d = py::array_t<double, py::array::f_style | py::array::forcecast>::ensure(a);  // column-major, as MATLAB
  if (!d) throw InputError("", where, "is not numeric");
  std::vector<size_t> dims;
  for (py::ssize_t i = 0; i < d.ndim(); ++i) dims.push_back(size_t(d.shape(i)));
  if (dims.empty()) dims = {1, 1};
  if (dims.size() == 1) dims = {dims[0], 1};
  return MatValue::array(dims, std::vector<double>(d.data(), d.data() + d.size()), single);
}

// MatValue -> Python: struct -> dict, char -> str, cell -> list, numeric -> numpy (column-major
// data in MATLAB's shape; scalars as float).
py::object from_mat(const MatValue& m) {
  switch (m.kind) {
    case MatValue::Kind::kStruct: {
      py::dict d;
      for (auto& [k, v] : m.fields) d[text(k)] = from_mat(v);
      return d;
    }
    case MatValue::Kind::kText: return text(m.text);
    case MatValue::Kind::kCell: {
      py::list l;
      for (auto& c : m.cells) l.append(from_mat(c));
      return l;
    }
    case MatValue::Kind::kNumeric: {
      if (m.numbers.size() == 1) return py::float_(m.numbers[0]);
      std::vector<py::ssize_t> shape(m.dims.begin(), m.dims.end()), strides;
      py::ssize_t st = sizeof(double);
      for (size_t d : m.dims) { strides.push_back(st); st *= py::ssize_t(d); }
      py::array_t<double> a(shape, strides);
      std::copy(m.numbers.begin(), m.numbers.end(), a.mutable_data());
      if (m.single) return a.attr("astype")("float32");
      return a;
    }
    case MatValue::Kind::kUnsupported: return py::str("<unsupported: " + m.unsupported + ">");
    default: return py::none();
  }
}

py::dict export_iset(const py::object& image, const py::object& path_in, const std::string& name,
                     const py::object& distance_in, const py::object& hfov_in, const std::string& source) {
  const SpectralImage& img = image_arg(image, "image");
  const std::string path = path_arg(path_in, "path");
  std::optional<double> distance, hfov;  // the CLI's --distance (> 0) and --hfov ranges
  if (!distance_in.is_none()) distance = float_arg(distance_in, "distance_m", 1e-12, 1e12);
  if (!hfov_in.is_none()) hfov = float_arg(hfov_in, "hfov_deg", 1e-6, 179.9);
  IsetScene s = make_iset_scene(img, {name, distance, hfov}, source);
  write_iset_scene(path, s);
  py::dict d;
  d["file"] = path;
  d["distance_m"] = s.distance_m;
  d["distance_source"] = s.distance_source;
  d["hfov_deg"] = s.hfov_deg;
  d["photon_sum"] = s.photon_sum;
  d["illuminant"] = s.has_illuminant;
  d["warnings"] = s.warnings;
  return d;
}

py::dict export_iset_oi(const py::object& image, const py::object& camera, const py::object& path_in) {
  const SpectralImage& img = image_arg(image, "image");
  CameraDescription cam = camera_arg(camera);
  const std::string path = path_arg(path_in, "path");
  IsetOi oi;
  run_without_gil(0, [&] { oi = make_iset_oi(img, cam, "<python image>"); });
  write_iset_oi(path, oi);
  py::dict d;
  d["file"] = path;
  d["rows"] = oi.rows;
  d["cols"] = oi.cols;
  d["hfov_deg"] = oi.hfov_deg;
  d["focal_length_m"] = oi.focal_length_m;
  d["pixel_pitch_m"] = oi.pixel_pitch_m;
  d["photon_sum"] = oi.photon_sum;
  d["warnings"] = oi.warnings;
  return d;
}

py::dict read_spectrum_file(const py::object& path) {
  CsvNumeric t = read_spectrum_table(path_arg(path, "path"));
  const size_t n = t.rows.size(), k = t.header.size() - 1;
  py::array_t<double> nm(n);
  py::dict cols;
  for (size_t i = 0; i < n; ++i) nm.mutable_at(i) = t.rows[i][0];
  for (size_t j = 0; j < k; ++j) {
    py::array_t<double> c(n);
    for (size_t i = 0; i < n; ++i) c.mutable_at(i) = t.rows[i][j + 1];
    cols[text(t.header[j + 1])] = c;
  }
  py::dict d;
  d["nm"] = nm;
  d["columns"] = cols;
  return d;
}

std::vector<std::string> str_list(const py::object& obj, const std::string& what) {
  std::vector<std::string> out;
  if (obj.is_none()) return out;
  if (py::isinstance<py::str>(obj)) return {obj.cast<std::string>()};
  for (auto x : items_of(obj, what, "a str or a list of str")) {
    if (!py::isinstance<py::str>(x)) throw InputError("", what, "expected a list of str, got an item of type " + type_name(x));
    out.push_back(x.cast<std::string>());
  }
  return out;
}

std::string str_arg(const py::object& obj, const std::string& what) {
  if (obj.is_none()) return "";
  if (!py::isinstance<py::str>(obj)) throw InputError("", what, "expected a str, got " + type_name(obj));
  return obj.cast<std::string>();
}

// Runs the job on a worker thread while this (Python's) thread waits with the GIL released, waking
// every 0.1 s to see Ctrl-C and to call `callback(done, total, step)`. Ctrl-C or a callback that
// returns False asks the job to stop (DiagnoseJob::progress); the candidates in flight finish, then
// KeyboardInterrupt is raised here (an exception raised by the callback is re-raised instead).
DiagnoseOutcome run_watched(DiagnoseJob job, int threads, const py::object& callback) {
  std::atomic<int> step{0};
  std::atomic<int64_t> done{0}, total{0};
  std::atomic<bool> stop{false};
  job.progress = [&](int s, int64_t d, int64_t t) {
    step = s;
    total = t;
    done = d;
    return !stop.load();
  };
  DiagnoseOutcome r;
  std::future<void> work = std::async(std::launch::async, [&] {
    if (threads > 0) {
      tbb::task_arena arena(threads);
      arena.execute([&] { r = run_diagnose_job(job); });
    } else {
      r = run_diagnose_job(job);
    }
  });
  bool keyboard = false;
  std::optional<py::error_already_set> failed;
  for (;;) {
    bool finished;
    {
      py::gil_scoped_release release;
      finished = work.wait_for(std::chrono::milliseconds(100)) == std::future_status::ready;
    }
    if (finished) break;
    if (stop) continue;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!callback.is_none()) {
        py::object go = callback(done.load(), total.load(), step.load());
        if (!go.is_none() && !PyObject_IsTrue(go.ptr())) stop = true;
      }
    } catch (py::error_already_set& e) {
      stop = true;
      if (e.matches(PyExc_KeyboardInterrupt)) keyboard = true;
      else failed = std::move(e);
    }
  }
  try {
    work.get();
  } catch (const Interrupted&) {
    if (failed) throw std::move(*failed);
    if (!keyboard) throw;  // the callback said stop: KeyboardInterrupt with the library's message
  }
  if (failed) throw std::move(*failed);
  if (keyboard) {
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }
  return r;
}

py::object diagnose(const py::object& input, const py::object& model, const py::object& where, const py::object& groups,
                    const py::object& z, const py::object& max_causes, const py::object& report_by, const py::object& out,
                    const py::object& fit_on, const py::object& predict, const py::object& shared_concentrations,
                    const py::object& threads, const py::object& progress) {
  DiagnoseJob job;
  job.input = path_arg(input, "input");
  job.model = path_arg(model, "model");
  job.where = str_list(where, "where");
  job.groups = str_list(groups, "groups");
  if (!z.is_none()) job.z = float_arg(z, "z", 0, 100);
  if (auto v = opt_int_arg(max_causes, "max_causes", 0, 1000)) job.max_causes = int(*v);
  job.report_by = str_arg(report_by, "report_by");
  job.outdir = out.is_none() ? "" : path_arg(out, "out");
  job.fit_on = str_arg(fit_on, "fit_on");
  job.predict = str_arg(predict, "predict");
  job.shared_concentrations = str_list(shared_concentrations, "shared_concentrations");
  job.json = true;
  const int n = threads_arg(threads);
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    throw InputError("", "progress", "expected None or a callable(done, total, step), got " + type_name(progress));
  DiagnoseOutcome r = run_watched(job, n, progress);
  py::dict d = from_json(r.report).cast<py::dict>();
  d["text"] = r.text;
  d["files"] = r.files;
  return d;
}

}  // namespace

void bind_interop(py::module_& m) {
  m.def("read_mat", [](const py::object& path) {
          py::dict d;
          for (auto& [k, v] : read_mat_file(path_arg(path, "path"))) d[text(k)] = from_mat(v);
          return d;
        }, py::arg("path"), "every variable of a .mat file: structs as dicts, text as str, cells as lists, arrays as numpy");
  m.def("write_mat", [](const py::object& path, const py::object& vars) {
          if (!py::isinstance<py::dict>(vars)) throw InputError("", "variables", "expected a dict {name: value}, got " + type_name(vars));
          MatVariables out;
          for (auto& [k, v] : vars.cast<py::dict>()) {
            if (!py::isinstance<py::str>(k)) throw InputError("", "variables", "names must be str");
            out.emplace_back(k.cast<std::string>(), to_mat(v, k.cast<std::string>()));
          }
          write_mat_file(path_arg(path, "path"), out);
        }, py::arg("path"), py::arg("variables"),
        "write a MAT 5 file: dicts become structs, str char arrays, lists of str cells, arrays/numbers double (float32 single)");
  m.def("export_iset", &export_iset, py::arg("image"), py::arg("path"), py::arg("name") = "", py::arg("distance_m") = py::none(),
        py::arg("hfov_deg") = py::none(), py::arg("source") = "<python image>",
        "write the image as an ISETCam scene struct (variable `scene`) to a .mat file; returns a summary");
  m.def("export_iset_oi", &export_iset_oi, py::arg("image"), py::arg("camera"), py::arg("path"),
        "write the optical image the camera's lens, filters and optics stage form from the image as an ISETCam oi "
        "(variable `oi`: sensor-plane irradiance in photons s^-1 m^-2 nm^-1 on the sensor grid); returns a summary");
  m.def("read_iset_scene", [](const py::object& p) { return read_iset_scene(path_arg(p, "path")); }, py::arg("path"),
        "an ISETCam scene .mat as a SpectralImage (W sr^-1 m^-2 nm^-1)");
  m.def("import_iset_sensor", [](const py::object& p) {
          IsetSensorImport s = import_iset_sensor(path_arg(p, "path"));
          return py::make_tuple(from_json(s.camera), s.notes);
        }, py::arg("path"), "an ISETCam sensor .mat as (camera.json dict, notes)");
  m.def("read_spectrum_file", &read_spectrum_file, py::arg("path"),
        "a spectrum CSV or ISETCam .mat (wavelength, data): {'nm': array, 'columns': {name: array}}");
  m.def("write_spectrum_mat", [](const py::object& path, const py::object& nm_in, const py::object& cols_in,
                                 const py::object& names_in, const std::string& comment) {
          auto numbers = [](const py::handle& o, const std::string& what) {
            auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
            if (!a || py::isinstance<py::str>(o) || a.ndim() != 1) throw InputError("", what, "expected a list or 1-D array of numbers");
            return std::vector<double>(a.data(), a.data() + a.size());
          };
          std::vector<double> nm = numbers(nm_in, "nm");
          std::vector<std::vector<double>> cols;
          for (auto c : items_of(cols_in, "columns", "a list of columns (each as many values as nm)")) cols.push_back(numbers(c, "columns"));
          std::vector<std::string> names;
          if (!names_in.is_none()) {
            for (auto n : items_of(names_in, "names", "a list of str")) {
              if (!py::isinstance<py::str>(n)) throw InputError("", "names", "expected a list of str");
              names.push_back(n.cast<std::string>());
            }
          }
          if (nm.empty()) throw InputError("", "nm", "no wavelengths");
          for (size_t i = 0; i < nm.size(); ++i)
            if (!std::isfinite(nm[i]) || (i > 0 && !(nm[i] > nm[i - 1]))) throw InputError("", "nm", "wavelengths must be finite and increase");
          for (auto& c : cols)
            if (c.size() != nm.size()) throw InputError("", "columns", "each column needs as many values as nm (" + std::to_string(nm.size()) + ")");
          if (!names.empty() && names.size() != cols.size()) throw InputError("", "names", "one name per column");
          write_spectrum_mat(path_arg(path, "path"), nm, cols, names, comment);
        }, py::arg("path"), py::arg("nm"), py::arg("columns"), py::arg("names") = py::none(),
        py::arg("comment") = "", "write an ISETCam spectral file (wavelength, data, filterNames, comment)");
  m.def("diagnose", &diagnose, py::arg("input"), py::arg("model"), py::arg("where") = py::none(),
        py::arg("groups") = py::none(), py::arg("z") = py::none(), py::arg("max_causes") = py::none(),
        py::arg("report_by") = py::none(), py::arg("out") = py::none(), py::arg("fit_on") = py::none(),
        py::arg("predict") = py::none(), py::arg("shared_concentrations") = py::none(), py::arg("threads") = py::none(),
        py::arg("progress") = py::none(),
        "run `oralfluor diagnose` on a folder or CSV with a model file; returns the JSON report as a dict (plus 'text'); "
        "fit_on='subject=B' [predict='subject=Z'] fits on some rows and predicts others with the global parameters fixed "
        "(CLI --fit-on/--predict); shared_concentrations=['subject','site','date'] fits one set of amounts per visit; "
        "threads: worker threads (None: all cores); progress: callable(done, total, step) called about every 0.1 s with the "
        "candidate causes tried in cause step `step`, returning False stops; Ctrl-C stops it (KeyboardInterrupt)");
}

}  // namespace ofl::python
