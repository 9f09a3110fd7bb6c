// Cameras (camera.json, a Python dict or an ISETCam sensor .mat) and the camera simulation on a
// spectral image, through the library call `oralfluor camera` uses (simulate_camera), so that the
// raw mosaic equals the CLI's raw.tiff for the same image, camera and seed.
#include "python/src/common.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"
#include "renderer/image/spectral_exr.h"

namespace ofl::python {
namespace {

struct CameraResult {
  CameraRun run;
  CameraDescription cam;
  CameraRunOptions opt;
  std::vector<float> mosaic_with_dark;  // expected electrons of each pixel's colour + dark (computed once)
};

CameraDescription camera_from(const py::object& src, const std::string& name) {
  if (py::isinstance<py::dict>(src)) return parse_camera(JsonFile::from(to_json(src, name), name).root());
  return load_camera(path_arg(src, "camera"));
}

}  // namespace

CameraDescription camera_arg(const py::object& src) {
  if (py::isinstance<CameraDescription>(src)) return src.cast<CameraDescription>();
  if (py::isinstance<py::dict>(src) || py::isinstance<py::str>(src) || py::hasattr(src, "__fspath__"))
    return camera_from(src, "<python camera>");
  throw InputError("", "camera", "expected a Camera, a camera file name or a camera dict, got " + type_name(src));
}

namespace {

CameraResult simulate(const py::object& image_in, const py::object& camera, const py::object& seed_in,
                      const py::object& noise_in, const py::object& threads_in, const std::string& radiance_name_in) {
  // A spectral EXR path is read here; an image or render result is used as it is.
  std::optional<SpectralImage> read;
  std::string radiance_name = radiance_name_in;
  if (py::isinstance<py::str>(image_in) || py::hasattr(image_in, "__fspath__")) {
    radiance_name = path_arg(image_in, "image");
    read = read_spectral_exr(radiance_name);
  }
  const SpectralImage& image = read ? *read : image_arg(image_in, "image");
  CameraDescription cam = camera_arg(camera);
  CameraResult r;
  r.cam = cam;
  r.opt.seed = seed_arg(seed_in, "seed");
  r.opt.noise = opt_bool_arg(noise_in, "noise");
  const int threads = threads_arg(threads_in);
  run_without_gil(threads, [&] {
    SpectralImage img = image;  // check_radiance clips negatives in place
    std::vector<std::string> input_warnings;
    check_radiance(img, radiance_name, &input_warnings);
    r.run = simulate_camera(img, cam, r.opt, radiance_name);
    for (auto& w : input_warnings) r.run.warnings.insert(r.run.warnings.begin(), w);
    r.run.summary["warnings"] = r.run.warnings;
    r.mosaic_with_dark = r.run.expected.mosaic_e;
    for (float& x : r.mosaic_with_dark) x += float(r.run.expected.dark_e);
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
      .def(py::init([](const py::object& source, const std::string& name) {
             if (!py::isinstance<py::dict>(source) && !py::isinstance<py::str>(source) && !py::hasattr(source, "__fspath__"))
               throw InputError("", "source", "expected a camera file name (str or pathlib.Path) or a camera dict, got " + type_name(source));
             return camera_from(source, name);
           }), py::arg("source"), py::arg("name") = "<python camera>",
           "from a camera.json path, an ISETCam sensor .mat path, or a dict in the camera.json format")
      .def_property_readonly("name", [](const CameraDescription& c) { return c.name; })
      .def_property_readonly("cfa", [](const CameraDescription& c) { return cfa_name(c.sensor.cfa); })
      .def("to_dict", [](const CameraDescription& c, const py::object& lo_in, const py::object& hi_in) {
             double lo = float_arg(lo_in, "lo_nm", 1, 1e5), hi = float_arg(hi_in, "hi_nm", 1, 1e5);
             if (!(hi > lo)) throw InputError("", "hi_nm", "must be above lo_nm");
             return from_json(camera_to_json(c, lo, hi));
           },
           py::arg("lo_nm") = 350.0, py::arg("hi_nm") = 830.0,
           "a self-contained camera.json document (spectra sampled every nm over [lo_nm, hi_nm])")
      .def("__repr__", [](const CameraDescription& c) { return "<oralfluor.Camera \"" + c.name + "\">"; });

  py::class_<CameraResult>(m, "CameraResult", "what `oralfluor camera` computes: raw mosaic, expected electrons, metadata")
      .def_property_readonly("raw", [](py::object self) {
             const auto& r = self.cast<const CameraResult&>();
             return view(r.run.raw.dn, {r.run.raw.height, r.run.raw.width}, self);
           }, "uint16 raw mosaic (rows, cols), DN including the black level (read-only view)")
      .def_property_readonly("electrons", [](py::object self) {
             const auto& e = self.cast<const CameraResult&>().run.expected;
             return view(e.channel_e, {e.height, e.width, 3}, self);
           }, "expected photo-electrons (rows, cols, 3): what R, G and B pixels would collect, noise free (read-only view)")
      .def_property_readonly("mosaic_electrons", [](py::object self) {
             const auto& r = self.cast<const CameraResult&>();
             return view(r.mosaic_with_dark, {r.run.expected.height, r.run.expected.width}, self);
           }, "expected electrons of each pixel's own colour plus the dark electrons (electrons.exr 'mosaic'; read-only view)")
      .def_property_readonly("dark_electrons", [](const CameraResult& r) { return r.run.expected.dark_e; })
      .def_property_readonly("metadata", [](const CameraResult& r) { return from_json(r.run.meta.numbers_json()); },
                             "cfa_pattern, black_level_dn, white_level_dn, bit depth, gains, exposure, seed, ...")
      .def_property_readonly("cfa", [](const CameraResult& r) { return cfa_name(r.run.meta.cfa); })
      .def_property_readonly("black_level", [](const CameraResult& r) { return r.run.meta.black_level_dn; })
      .def_property_readonly("white_level", [](const CameraResult& r) { return r.run.meta.white_level_dn; })
      .def_property_readonly("summary", [](const CameraResult& r) { return from_json(r.run.summary); })
      .def_property_readonly("warnings", [](const CameraResult& r) { return r.run.warnings; })
      .def_property_readonly("camera", [](const CameraResult& r) { return r.cam; })
      .def("write", [](const CameraResult& r, const py::object& folder) {
             CameraOutputs o = write_camera_outputs(r.run, r.cam, r.opt, path_arg(folder, "folder"));
             py::dict d;
             d["raw_tiff"] = o.raw_tiff.string();
             d["raw_json"] = o.raw_json.string();
             d["raw_dng"] = o.raw_dng.string();
             d["electrons_exr"] = o.electrons_exr.string();
             d["preview_png"] = o.preview_png.string();
             return d;
           }, py::arg("folder"), "write raw.tiff, raw.json, raw.dng, electrons.exr and camera_preview.png as the CLI does");

  m.def("simulate_camera", &simulate, py::arg("image"), py::arg("camera"), py::arg("seed") = py::none(),
        py::arg("noise") = py::none(), py::arg("threads") = py::none(), py::arg("radiance_name") = "<python image>",
        "run the camera model on a spectral image (a SpectralImage, a RenderResult or an EXR path) through a camera "
        "(a Camera, a camera.json or ISETCam sensor .mat path, or a dict); the GIL is released");
  m.def("read_raw", [](const py::object& path) {
          RawImage r = read_raw(path_arg(path, "path"));
          py::dict d;
          d["raw"] = mosaic(r.dn, r.height, r.width);
          d["metadata"] = from_json(r.meta.numbers_json());
          d["sidecar"] = from_json(r.sidecar);
          return d;
        }, py::arg("path"), "read a raw.tiff written by `oralfluor camera` (with its raw.json)");
}

}  // namespace ofl::python
