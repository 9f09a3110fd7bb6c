// Cameras (camera.json, a Python dict or an ISETCam sensor .mat) and the camera simulation on a
// spectral image, through the library call `oralfluor camera` uses (simulate_camera), so that the
// raw mosaic equals the CLI's raw.tiff for the same image, camera and seed.
#include "python/src/common.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/core/error.h"
#include "renderer/core/json_node.h"

namespace ofl::python {
namespace {

struct CameraResult {
  CameraRun run;
  CameraDescription cam;
  CameraRunOptions opt;
};

CameraDescription camera_from(const py::object& src, const std::string& name) {
  if (py::isinstance<py::dict>(src)) return parse_camera(JsonFile::from(to_json(src, name), name).root());
  std::string path = py::str(src).cast<std::string>();
  return load_camera(path);
}

CameraResult simulate(const SpectralImage& image, const CameraDescription& cam, std::optional<uint64_t> seed,
                      std::optional<bool> noise, int threads, const std::string& radiance_name) {
  CameraResult r;
  r.cam = cam;
  r.opt.seed = seed;
  r.opt.noise = noise;
  run_without_gil(threads, [&] {
    SpectralImage img = image;  // check_radiance clips negatives in place
    std::vector<std::string> input_warnings;
    check_radiance(img, radiance_name, &input_warnings);
    r.run = simulate_camera(img, cam, r.opt, radiance_name);
    for (auto& w : input_warnings) r.run.warnings.insert(r.run.warnings.begin(), w);
    r.run.summary["warnings"] = r.run.warnings;
  });
  return r;
}

py::array_t<uint16_t> mosaic(const std::vector<uint16_t>& dn, int h, int w) {
  py::array_t<uint16_t> a({h, w});
  std::copy(dn.begin(), dn.end(), a.mutable_data());
  return a;
}

}  // namespace

void bind_camera(py::module_& m) {
  py::class_<CameraDescription>(m, "Camera", "a camera: lens, filter stack and sensor (docs/camera.md)")
      .def(py::init(&camera_from), py::arg("source"), py::arg("name") = "<python camera>",
           "from a camera.json path, an ISETCam sensor .mat path, or a dict in the camera.json format")
      .def_property_readonly("name", [](const CameraDescription& c) { return c.name; })
      .def_property_readonly("cfa", [](const CameraDescription& c) { return cfa_name(c.sensor.cfa); })
      .def("to_dict", [](const CameraDescription& c, double lo, double hi) { return from_json(camera_to_json(c, lo, hi)); },
           py::arg("lo_nm") = 350.0, py::arg("hi_nm") = 830.0,
           "a self-contained camera.json document (spectra sampled every nm over [lo_nm, hi_nm])")
      .def("__repr__", [](const CameraDescription& c) { return "<oralfluor.Camera \"" + c.name + "\">"; });

  py::class_<CameraResult>(m, "CameraResult", "what `oralfluor camera` computes: raw mosaic, expected electrons, metadata")
      .def_property_readonly("raw", [](const CameraResult& r) { return mosaic(r.run.raw.dn, r.run.raw.height, r.run.raw.width); },
                             "uint16 raw mosaic (rows, cols), DN including the black level")
      .def_property_readonly("electrons",
                             [](const CameraResult& r) {
                               const auto& e = r.run.expected;
                               return cube(e.channel_e, e.height, e.width, 3);
                             },
                             "expected photo-electrons (rows, cols, 3): what R, G and B pixels would collect, noise free")
      .def_property_readonly("mosaic_electrons",
                             [](const CameraResult& r) {
                               const auto& e = r.run.expected;
                               std::vector<float> v(e.mosaic_e);
                               for (float& x : v) x += float(e.dark_e);
                               return plane(v, e.height, e.width);
                             },
                             "expected electrons of each pixel's own colour plus the dark electrons (electrons.exr 'mosaic')")
      .def_property_readonly("dark_electrons", [](const CameraResult& r) { return r.run.expected.dark_e; })
      .def_property_readonly("metadata", [](const CameraResult& r) { return from_json(r.run.meta.numbers_json()); },
                             "cfa_pattern, black_level_dn, white_level_dn, bit depth, gains, exposure, seed, ...")
      .def_property_readonly("cfa", [](const CameraResult& r) { return cfa_name(r.run.meta.cfa); })
      .def_property_readonly("black_level", [](const CameraResult& r) { return r.run.meta.black_level_dn; })
      .def_property_readonly("white_level", [](const CameraResult& r) { return r.run.meta.white_level_dn; })
      .def_property_readonly("summary", [](const CameraResult& r) { return from_json(r.run.summary); })
      .def_property_readonly("warnings", [](const CameraResult& r) { return r.run.warnings; })
      .def_property_readonly("camera", [](const CameraResult& r) { return r.cam; })
      .def("write", [](const CameraResult& r, const std::string& dir) {
             CameraOutputs o = write_camera_outputs(r.run, r.cam, r.opt, dir);
             py::dict d;
             d["raw_tiff"] = o.raw_tiff.string();
             d["raw_json"] = o.raw_json.string();
             d["raw_dng"] = o.raw_dng.string();
             d["electrons_exr"] = o.electrons_exr.string();
             d["preview_png"] = o.preview_png.string();
             return d;
           }, py::arg("folder"), "write raw.tiff, raw.json, raw.dng, electrons.exr and camera_preview.png as the CLI does");

  m.def("simulate_camera", &simulate, py::arg("image"), py::arg("camera"), py::arg("seed") = py::none(),
        py::arg("noise") = py::none(), py::arg("threads") = 0, py::arg("radiance_name") = "<python image>",
        "run the camera model on a spectral image (the GIL is released)");
  m.def("read_raw", [](const std::string& path) {
          RawImage r = read_raw(path);
          py::dict d;
          d["raw"] = mosaic(r.dn, r.height, r.width);
          d["metadata"] = from_json(r.meta.numbers_json());
          d["sidecar"] = from_json(r.sidecar);
          return d;
        }, py::arg("path"), "read a raw.tiff written by `oralfluor camera` (with its raw.json)");
}

}  // namespace ofl::python
