// MATLAB/ISETCam exchange (.mat through libmatio) and `oralfluor diagnose` as a call returning dicts.
#include "python/src/common.h"
#include "renderer/core/error.h"
#include "renderer/diagnose/diagnose_job.h"
#include "renderer/interop/iset_scene.h"
#include "renderer/interop/iset_sensor.h"
#include "renderer/interop/mat_file.h"
#include "renderer/interop/mat_spectrum.h"
#include "renderer/spectral/spectrum.h"

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
      for (auto& [k, v] : m.fields) d[py::str(k)] = from_mat(v);
      return d;
    }
    case MatValue::Kind::kText: return py::str(m.text);
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

py::dict export_iset(const SpectralImage& img, const std::string& path, const std::string& name,
                     std::optional<double> distance, std::optional<double> hfov, const std::string& source) {
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

py::dict read_spectrum_file(const std::string& path) {
  CsvNumeric t = read_spectrum_table(path);
  const size_t n = t.rows.size(), k = t.header.size() - 1;
  py::array_t<double> nm(n);
  py::dict cols;
  for (size_t i = 0; i < n; ++i) nm.mutable_at(i) = t.rows[i][0];
  for (size_t j = 0; j < k; ++j) {
    py::array_t<double> c(n);
    for (size_t i = 0; i < n; ++i) c.mutable_at(i) = t.rows[i][j + 1];
    cols[py::str(t.header[j + 1])] = c;
  }
  py::dict d;
  d["nm"] = nm;
  d["columns"] = cols;
  return d;
}

py::object diagnose(const std::string& input, const std::string& model, const std::vector<std::string>& where,
                    const std::vector<std::string>& groups, std::optional<double> z, std::optional<int> max_causes,
                    const std::string& report_by, const std::string& out, const std::string& fit_on, const std::string& predict,
                    const std::vector<std::string>& shared_concentrations) {
  DiagnoseJob job;
  job.input = input;
  job.model = model;
  job.where = where;
  job.groups = groups;
  job.z = z;
  job.max_causes = max_causes;
  job.report_by = report_by;
  job.outdir = out;
  job.fit_on = fit_on;
  job.predict = predict;
  job.shared_concentrations = shared_concentrations;
  job.json = true;
  DiagnoseOutcome r;
  run_without_gil(0, [&] { r = run_diagnose_job(job); });
  py::dict d = from_json(r.report).cast<py::dict>();
  d["text"] = r.text;
  d["files"] = r.files;
  return d;
}

}  // namespace

void bind_interop(py::module_& m) {
  m.def("read_mat", [](const std::string& path) {
          py::dict d;
          for (auto& [k, v] : read_mat_file(path)) d[py::str(k)] = from_mat(v);
          return d;
        }, py::arg("path"), "every variable of a .mat file: structs as dicts, text as str, cells as lists, arrays as numpy");
  m.def("write_mat", [](const std::string& path, const py::dict& vars) {
          MatVariables out;
          for (auto& [k, v] : vars) out.emplace_back(py::str(k).cast<std::string>(), to_mat(v, py::str(k).cast<std::string>()));
          write_mat_file(path, out);
        }, py::arg("path"), py::arg("variables"),
        "write a MAT 5 file: dicts become structs, str char arrays, lists of str cells, arrays/numbers double (float32 single)");
  m.def("export_iset", &export_iset, py::arg("image"), py::arg("path"), py::arg("name") = "", py::arg("distance_m") = py::none(),
        py::arg("hfov_deg") = py::none(), py::arg("source") = "<python image>",
        "write the image as an ISETCam scene struct (variable `scene`) to a .mat file; returns a summary");
  m.def("read_iset_scene", [](const std::string& p) { return read_iset_scene(p); }, py::arg("path"),
        "an ISETCam scene .mat as a SpectralImage (W sr^-1 m^-2 nm^-1)");
  m.def("import_iset_sensor", [](const std::string& p) {
          IsetSensorImport s = import_iset_sensor(p);
          return py::make_tuple(from_json(s.camera), s.notes);
        }, py::arg("path"), "an ISETCam sensor .mat as (camera.json dict, notes)");
  m.def("read_spectrum_file", &read_spectrum_file, py::arg("path"),
        "a spectrum CSV or ISETCam .mat (wavelength, data): {'nm': array, 'columns': {name: array}}");
  m.def("write_spectrum_mat", [](const std::string& path, const std::vector<double>& nm, const std::vector<std::vector<double>>& cols,
                                 const std::vector<std::string>& names, const std::string& comment) {
          write_spectrum_mat(path, nm, cols, names, comment);
        }, py::arg("path"), py::arg("nm"), py::arg("columns"), py::arg("names") = std::vector<std::string>{},
        py::arg("comment") = "", "write an ISETCam spectral file (wavelength, data, filterNames, comment)");
  m.def("diagnose", &diagnose, py::arg("input"), py::arg("model"), py::arg("where") = std::vector<std::string>{},
        py::arg("groups") = std::vector<std::string>{}, py::arg("z") = py::none(), py::arg("max_causes") = py::none(),
        py::arg("report_by") = "", py::arg("out") = "", py::arg("fit_on") = "", py::arg("predict") = "",
        py::arg("shared_concentrations") = std::vector<std::string>{},
        "run `oralfluor diagnose` on a folder or CSV with a model file; returns the JSON report as a dict (plus 'text'); "
        "fit_on='subject=B' [predict='subject=Z'] fits on some rows and predicts others with the global parameters fixed "
        "(CLI --fit-on/--predict); shared_concentrations=['subject','site','date'] fits one set of amounts per visit");
}

}  // namespace ofl::python
