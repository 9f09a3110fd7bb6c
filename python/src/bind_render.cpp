// Scenes (from a file or a Python dict) and rendering with the GIL released, a progress callback
// that takes the GIL back, and Ctrl-C ending the render after the current pass (what finished is
// returned, flagged as interrupted), as the CLI does.
#include "python/src/common.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/render/render_job.h"

namespace ofl::python {
namespace {

nlohmann::json render_stats(const Scene& scene, const RenderStats& s) {
  return {{"scene", scene.file},
          {"width", scene.camera.width},
          {"height", scene.camera.height},
          {"spp", s.spp_done},
          {"spp_requested", scene.integrator.spp},
          {"seed", scene.integrator.seed},
          {"interrupted", s.interrupted},
          {"build_seconds", s.build_seconds},
          {"render_seconds", s.seconds},
          {"camera_samples_per_second", s.samples_per_second()},
          {"rays", s.rays.total()},
          {"rays_per_second", s.rays_per_second()},
          {"relative_noise", s.relative_noise}};
}

// Summed on-axis spectral intensity of the scene's LEDs on the transport grid (what a render records
// as oralfluor.excitation_spd).
nlohmann::json excitation_spd(const Scene& scene) {
  const WavelengthGrid& g = scene.grid();
  std::vector<double> nm, w(g.size(), 0.0);
  for (int i = 0; i < g.size(); ++i) nm.push_back(g.wavelength(i));
  for (const auto& l : scene.lights)
    for (int i = 0; i < g.size(); ++i) w[i] += l.spectral_intensity[i];
  return {{"nm", nm}, {"W_per_sr_nm", w}};
}

py::object scene_info(const py::object& doc, const std::string& name) {
  JsonFile f = JsonFile::from(to_json(doc, name), name);
  Scene scene;
  run_without_gil(0, [&] { scene = load_scene(f); });
  std::vector<double> bands;
  for (int b = 0; b < scene.integrator.bands.size(); ++b) bands.push_back(scene.integrator.bands.centre(b));
  std::vector<std::string> materials;
  for (auto& m : scene.materials) materials.push_back(m.name);
  const auto& g = scene.grid();
  nlohmann::json j = {{"file", scene.file},
                      {"width", scene.camera.width},
                      {"height", scene.camera.height},
                      {"vfov_deg", scene.camera.vfov_deg},
                      {"spp", scene.integrator.spp},
                      {"seed", scene.integrator.seed},
                      {"grid_nm", {g.min_nm, g.max_nm, g.step_nm}},
                      {"bands_nm", bands},
                      {"band_step_nm", scene.integrator.bands.step_nm},
                      {"materials", materials},
                      {"lights", scene.lights.size()},
                      {"excitation_spd", excitation_spd(scene)}};
  return from_json(j);
}

// The CLI's ranges for render's overrides (renderer/cli/images/cmd_render.cpp, --spp/--width/--height).
SceneOverrides overrides(const py::object& spp, const py::object& seed, const py::object& width, const py::object& height) {
  SceneOverrides ov;
  if (auto v = opt_int_arg(spp, "spp", 1, 1 << 24)) ov.spp = int(*v);
  ov.seed = seed_arg(seed, "seed");
  if (auto v = opt_int_arg(width, "width", 1, 16384)) ov.width = int(*v);
  if (auto v = opt_int_arg(height, "height", 1, 16384)) ov.height = int(*v);
  return ov;
}

py::tuple render_doc(const py::object& doc, const std::string& name, const py::object& spp, const py::object& seed,
                     const py::object& width, const py::object& height, const py::object& threads_in, const py::object& aovs_in,
                     const py::object& fluorescence_in, const py::object& callback) {
  SceneOverrides ov = overrides(spp, seed, width, height);
  const int threads = threads_arg(threads_in);
  const bool aovs = opt_bool_arg(aovs_in, "aovs").value_or(true);
  const bool fluorescence = opt_bool_arg(fluorescence_in, "fluorescence").value_or(true);
  if (!callback.is_none() && !PyCallable_Check(callback.ptr()))
    throw InputError("", "progress", "expected True, False, None or a callable(done, total), got " + type_name(callback));
  JsonFile f = JsonFile::from(to_json(doc, name), name);
  bool keyboard = false, failed = false;
  RenderOptions opt;
  opt.progress = false;  // Python shows its own progress (oralfluor.render(progress=...))
  opt.aovs = aovs;
  opt.fluorescence_layer = fluorescence;
  opt.progress_callback = [&](int64_t done, int64_t total) -> bool {
    py::gil_scoped_acquire gil;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      if (!callback.is_none()) {
        py::object keep_going = callback(done, total);
        if (!keep_going.is_none() && !keep_going.cast<bool>()) return false;
      }
      return true;
    } catch (py::error_already_set& e) {
      if (e.matches(PyExc_KeyboardInterrupt)) {
        keyboard = true;
      } else {
        failed = true;
        e.restore();  // re-raised once the render has stopped
      }
      return false;
    }
  };
  Scene scene;
  RenderResult r;
  run_without_gil(threads, [&] {
    scene = load_scene(f, ov);
    r = render(scene, opt);
  });
  if (failed) throw py::error_already_set();
  (void)keyboard;  // an interrupted render is returned with stats["interrupted"] = True
  return py::make_tuple(std::move(r.image), from_json(render_stats(scene, r.stats)));
}

}  // namespace

void bind_render(py::module_& m) {
  m.def("_read_json", [](const py::object& path) { return from_json(JsonFile::load(path_arg(path, "scene")).doc()); }, py::arg("path"),
        "a JSON file as Python objects (InputError with line and column for malformed JSON)");
  m.def("_scene_info", &scene_info, py::arg("doc"), py::arg("name"),
        "load a scene document (validating every field) and summarise it");
  m.def("_render", &render_doc, py::arg("doc"), py::arg("name"), py::arg("spp") = py::none(), py::arg("seed") = py::none(),
        py::arg("width") = py::none(), py::arg("height") = py::none(), py::arg("threads") = py::none(), py::arg("aovs") = true,
        py::arg("fluorescence") = true, py::arg("callback") = py::none(),
        "render a scene document; returns (SpectralImage, stats dict)");
}

}  // namespace ofl::python
