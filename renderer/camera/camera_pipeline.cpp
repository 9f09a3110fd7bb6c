#include "renderer/camera/camera_pipeline.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>

#include "renderer/camera/optics/optics.h"
#include "renderer/camera/raw/camera_color.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/progress.h"
#include "renderer/image/image_file.h"
#include "renderer/spectral/spectra/band_coverage.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

std::vector<std::string> lost_light_warnings(const SpectralImage& img, const CameraDescription& cam,
                                             std::vector<std::string>* notes) {
  std::vector<std::string> out;
  auto lo = img.band_lo(), hi = img.band_hi();
  if (lo.empty()) return out;
  double outside = response_outside_bands(cam, lo, hi);
  if (outside > 0.01) {
    std::ostringstream w;
    w << "the image's bands (" << lo.front() << "-" << hi.back() << " nm) miss " << outside * 100.0
      << " % of the camera's response to a flat spectrum; light there is not simulated";
    out.push_back(w.str());
  }
  // The render records the LEDs' summed spectrum: light they emit outside the bands (an excitation
  // leak through the emission filter, say) never reaches the simulated sensor.
  auto it = img.attributes.find("oralfluor.excitation_spd");
  if (it == img.attributes.end()) return out;
  auto j = nlohmann::json::parse(it->second, nullptr, false);
  std::vector<double> nm, w;
  if (!j.is_discarded() && j.is_object() && j.contains("nm") && j.contains("W_per_sr_nm")) try {
      nm = j["nm"].get<std::vector<double>>();
      w = j["W_per_sr_nm"].get<std::vector<double>>();
    } catch (const nlohmann::json::exception&) {
      nm.clear();
    }
  WavelengthGrid g;
  if (nm.size() >= 2 && nm.size() == w.size()) g = {nm.front(), nm.back(), (nm.back() - nm.front()) / (nm.size() - 1)};
  if (nm.size() < 2 || nm.size() != w.size() || !(g.step_nm > 0)) {
    if (notes) notes->push_back("ignoring oralfluor.excitation_spd (not {nm, W_per_sr_nm} arrays of one length)");
    return out;
  }
  std::string lost = coverage_warning(band_coverage(g, w, lo, hi), "the scene's LED light", lo.front(), hi.back());
  if (!lost.empty()) out.push_back(lost + "; render with output_bands covering it (the default covers the whole grid)");
  return out;
}

namespace {
std::string suffix_with_digits(double exposure_s, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "_%.*gms", digits, exposure_s * 1e3);
  return b;
}
}  // namespace

std::string exposure_suffix(double exposure_s) { return suffix_with_digits(exposure_s, 4); }

std::vector<std::string> exposure_suffixes(const std::vector<double>& exposures_s) {
  std::vector<std::string> names;
  for (int digits = 4; digits <= 17; ++digits) {
    names.clear();
    for (double t : exposures_s) names.push_back(suffix_with_digits(t, digits));
    std::vector<std::string> sorted = names;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end()) break;
  }
  return names;
}

namespace {

// Value below which `pct` % of the pixels' expected electrons (own channel + dark) lie.
double electron_percentile(const ExpectedSignal& e, double pct) {
  std::vector<float> v(e.mosaic_e);
  if (v.empty()) return 0.0;
  size_t k = std::min(v.size() - 1, static_cast<size_t>(std::ceil(pct / 100.0 * v.size())) - (pct > 0 ? 1 : 0));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k] + e.dark_e;
}

// Fixed or auto exposure. Expected electrons (photo and dark) are proportional to the exposure,
// so one noise-free evaluation at the starting exposure gives the auto exposure in closed form; it
// is left in `*start` (at `*start_s`) for the caller to scale instead of evaluating again.
ExposureChoice choose_exposure(const SpectralImage& img, const CameraDescription& cam, const FieldGeometry& g,
                               const CameraRunOptions& opt, std::vector<std::string>* warnings, ExpectedSignal* start,
                               double* start_s) {
  ExposureChoice c;
  double t0 = opt.exposure_s.value_or(cam.sensor.exposure_s);
  c.exposure_s = t0;
  c.how = {{"mode", opt.exposure_s ? "fixed (--exposure)" : "fixed (camera)"}};
  if (opt.auto_exposure) {
    CameraDescription at = cam;
    at.sensor.exposure_s = t0;
    *start = expected_electrons(img, at, g);
    *start_s = t0;
    double e = electron_percentile(*start, opt.auto_percentile);
    double want = opt.auto_target * cam.sensor.full_well_e;
    c.how = {{"mode", "auto"}, {"target_full_well", opt.auto_target}, {"percentile", opt.auto_percentile},
             {"start_exposure_s", t0}, {"electrons_at_start", e}};
    if (e > 0) {
      double t = t0 * want / e;
      constexpr double kMin = 1e-6, kMax = 60.0;
      if (t < kMin || t > kMax) {
        char b[200];
        std::snprintf(b, sizeof b, "auto exposure wants %.3g s; limited to %.3g s", t, std::clamp(t, kMin, kMax));
        warnings->push_back(b);
        t = std::clamp(t, kMin, kMax);
      }
      c.exposure_s = t;
    } else {
      warnings->push_back("auto exposure: the image gives no electrons; the starting exposure is kept");
    }
  }
  if (opt.exposure_scale != 1.0) {
    c.how["bracket_factor"] = opt.exposure_scale;
    c.exposure_s *= opt.exposure_scale;
  }
  c.how["exposure_s"] = c.exposure_s;
  return c;
}

// The exposure (fixed or automatic) and the expected electrons at it: automatic exposure has
// evaluated the image already, and electrons scale with the exposure.
void expose(const SpectralImage& img, const CameraRunOptions& opt, CameraRun& run) {
  double start_s = 0;
  run.exposure = choose_exposure(img, run.camera, run.geometry, opt, &run.warnings, &run.expected, &start_s);
  run.camera.sensor.exposure_s = run.exposure.exposure_s;
  if (start_s > 0) {
    const double k = run.exposure.exposure_s / start_s;
    for (float& e : run.expected.channel_e) e = static_cast<float>(e * k);
    for (float& e : run.expected.mosaic_e) e = static_cast<float>(e * k);
    run.expected.dark_e *= k;
  } else {
    run.expected = expected_electrons(img, run.camera, run.geometry);
  }
}

// What raw.json records: the sensor's levels and gains, the lens, the camera and radiance it came
// from, the EXR's oralfluor attributes and the field geometry.
RawMetadata raw_metadata(const CameraRun& run, const SpectralImage& radiance, const SpectralImage& img,
                         const OpticalImage& optical, bool noise, uint64_t seed, const std::string& radiance_file) {
  const CameraDescription& cam = run.camera;
  const SensorDescription& s = cam.sensor;
  auto lo = img.band_lo(), hi = img.band_hi();
  RawMetadata m;
  m.width = img.width;
  m.height = img.height;
  m.cfa = s.cfa;
  m.black_level_dn = s.black_level_dn;
  m.white_level_dn = s.white_level_dn();
  m.adc_max_dn = s.adc_max_dn();
  m.bit_depth = s.bit_depth;
  m.exposure_s = s.exposure_s;
  m.system_gain_dn_per_e = s.system_gain_dn_per_e;
  m.analog_gain = s.analog_gain;
  m.full_well_e = s.full_well_e;
  m.noise = noise;
  m.seed = seed;
  m.camera_name = cam.name;
  m.f_number = cam.lens.f_number;
  m.focal_length_mm = cam.lens.focal_length_mm;
  m.capture_time = capture_time_text(radiance_file);
  nlohmann::json attrs = nlohmann::json::object();
  for (const auto& [k, v] : img.attributes)
    if (k.rfind("oralfluor.", 0) == 0) attrs[k] = v;
  m.extra["camera"] = camera_to_json(cam, lo.front(), hi.back());
  m.extra["camera_file"] = cam.source;
  m.extra["radiance"] = {{"file", radiance_file}, {"width", radiance.width}, {"height", radiance.height},
                         {"band_nm", img.band_nm}, {"band_lo_nm", lo}, {"band_hi_nm", hi}};
  m.extra["exr_attributes"] = attrs;
  m.extra["field_geometry"] = run.geometry.to_json();
  if (cam.optics.enabled) m.extra["optics"] = optical.info;
  return m;
}

// Per CFA channel: pixels, mean expected electrons (photo + dark), raw means and the saturated
// share; `saturated` gets the count over all channels.
nlohmann::json channel_summary(const CameraRun& run, int width, int height, size_t* saturated) {
  nlohmann::json channels = nlohmann::json::object();
  double sums[3][3] = {{0}};  // [channel][expected e, dn, saturated]
  size_t counts[3] = {0, 0, 0};
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      size_t i = static_cast<size_t>(y) * width + x;
      int c = cfa_channel(run.meta.cfa, x, y);
      sums[c][0] += run.expected.mosaic_e[i] + run.expected.dark_e;
      sums[c][1] += run.raw.dn[i];
      sums[c][2] += run.raw.dn[i] >= run.meta.white_level_dn;
      ++counts[c];
    }
  *saturated = 0;
  for (int c = 0; c < 3; ++c) {
    double n = std::max<size_t>(counts[c], 1);
    channels[channel_name(c)] = {{"pixels", counts[c]},
                                 {"mean_expected_electrons", sums[c][0] / n},
                                 {"mean_dn", sums[c][1] / n},
                                 {"mean_dn_above_black", sums[c][1] / n - run.meta.black_level_dn},
                                 {"saturated_fraction", sums[c][2] / n}};
    *saturated += static_cast<size_t>(sums[c][2]);
  }
  return channels;
}

// The run's summary (printed by `oralfluor camera --json` and kept in a sweep point's result).
nlohmann::json camera_summary(const CameraRun& run, const OpticalImage& optical, const std::string& radiance_file) {
  const CameraDescription& cam = run.camera;
  const SensorDescription& s = cam.sensor;
  const RawMetadata& m = run.meta;
  size_t saturated = 0;
  nlohmann::json channels = channel_summary(run, m.width, m.height, &saturated);
  double npx = static_cast<double>(m.width) * m.height;
  nlohmann::json summary = {{"camera", cam.name},
                            {"radiance", radiance_file},
                            {"width", m.width},
                            {"height", m.height},
                            {"cfa_pattern", cfa_name(s.cfa)},
                            {"noise", m.noise},
                            {"seed", m.seed},
                            {"exposure_s", s.exposure_s},
                            {"exposure", run.exposure.how},
                            {"total_gain_dn_per_e", s.total_gain()},
                            {"black_level_dn", m.black_level_dn},
                            {"white_level_dn", m.white_level_dn},
                            {"dark_electrons", run.expected.dark_e},
                            {"channels", channels},
                            {"saturated_fraction", saturated / npx},
                            {"full_well_clipped_fraction", run.raw.full_well_clipped / npx},
                            {"adc_clipped_fraction", run.raw.adc_clipped / npx},
                            {"field_geometry", run.geometry.to_json()},
                            {"warnings", run.warnings}};
  if (cam.optics.enabled) summary["optics"] = optical.info;
  return summary;
}

}  // namespace

FieldGeometry sensor_field_geometry(const SpectralImage& img, const CameraDescription& cam, double axis_x_px, double axis_y_px,
                                    std::vector<std::string>* warnings) {
  FieldGeometry g = make_field_geometry(cam.lens, cam.sensor, img.width, img.height,
                                        cam.optics.enabled ? std::nullopt : render_vfov_deg(img, warnings), warnings);
  g.axis_x_px = axis_x_px;
  g.axis_y_px = axis_y_px;
  if (cam.lens.sensor_cra_deg >= 0) {  // the CRA is given at the farthest corner, which the axis offset moves
    double rmax = g.max_radius_px();
    g.sensor_tan_per_px = rmax > 0 ? std::tan(cam.lens.sensor_cra_deg * kPi / 180.0) / rmax : 0.0;
  }
  return g;
}

CameraRun simulate_camera(const SpectralImage& radiance, const CameraDescription& cam_in, const CameraRunOptions& opt,
                          const std::string& radiance_file) {
  CameraRun run;
  run.camera = cam_in;
  const CameraDescription& cam = run.camera;
  // With an "optics" section the sensor sees the optical image (PSF, own grid), else the radiance itself.
  OpticalImage optical;
  if (cam.optics.enabled) {
    optical = form_optical_image(radiance, cam, radiance_file);
    run.warnings.insert(run.warnings.end(), optical.warnings.begin(), optical.warnings.end());
  }
  const SpectralImage& img = cam.optics.enabled ? optical.image : radiance;
  run.geometry = sensor_field_geometry(img, cam, optical.axis_x_px, optical.axis_y_px, &run.warnings);
  if (run.geometry.source == FieldGeometry::Source::kNone && cam.filters.any_interference() && cam.lens.sensor_cra_deg < 0)
    run.warnings.push_back("interference filters are evaluated at normal incidence everywhere (no field angles)");
  if (auto u = img.attributes.find("emissiveUnits"); u != img.attributes.end() && u->second != "W.m^-2.sr^-1")
    run.warnings.push_back("the EXR's emissiveUnits are \"" + u->second +
                           "\", not W.m^-2.sr^-1: electron counts assume W sr^-1 m^-2 nm^-1");
  std::vector<std::string> lost = lost_light_warnings(img, cam, &run.warnings);
  if (opt.strict_bands && !lost.empty()) throw InputError(radiance_file, "bands", lost.front() + " (--strict)");
  run.warnings.insert(run.warnings.end(), lost.begin(), lost.end());
  expose(img, opt, run);
  throw_if_interrupted("simulating the camera (this exposure's files were not written)");
  bool noise = opt.noise.value_or(cam.noise);
  uint64_t seed = opt.seed.value_or(cam.seed);
  const SensorDescription& s = cam.sensor;
  FixedPattern fixed = noise ? make_fixed_pattern(s, img.width, img.height) : FixedPattern{};
  run.raw = simulate_raw(run.expected.mosaic_e, img.width, img.height, s, noise, seed, fixed);
  run.meta = raw_metadata(run, radiance, img, optical, noise, seed, radiance_file);
  run.summary = camera_summary(run, optical, radiance_file);
  return run;
}

void write_electrons_exr(const std::filesystem::path& file, const ExpectedSignal& e, const nlohmann::json& attributes) {
  OIIO::ImageSpec spec(e.width, e.height, 4, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B", "mosaic"};
  spec.attribute("compression", "zip");
  spec.attribute("oralfluor.units", "electrons (expected, noise-free)");
  spec.attribute("oralfluor.channels",
                 "R, G, B: photo-electrons each colour would collect at the pixel; mosaic: the pixel's own CFA "
                 "colour plus the expected dark electrons");
  for (auto it = attributes.begin(); it != attributes.end(); ++it)
    spec.attribute("oralfluor." + it.key(), it.value().is_string() ? it.value().get<std::string>() : it.value().dump());
  std::vector<float> px(static_cast<size_t>(e.width) * e.height * 4);
  for (size_t i = 0; i < e.mosaic_e.size(); ++i) {
    for (int c = 0; c < 3; ++c) px[i * 4 + c] = e.channel_e[i * 3 + c];
    px[i * 4 + 3] = static_cast<float>(e.mosaic_e[i] + e.dark_e);
  }
  write_image_file(file, spec, px.data());
}

CameraOutputs write_camera_outputs(const CameraRun& run, const CameraDescription& cam, const CameraRunOptions& opt,
                                   const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir, ec)) throw InputError(dir.string(), "", "cannot create output folder");
  CameraOutputs o;
  const std::string& x = opt.output_suffix;
  o.raw_tiff = dir / ("raw" + x + ".tiff");
  o.raw_json = dir / ("raw" + x + ".json");
  o.electrons_exr = dir / ("electrons" + x + ".exr");
  o.preview_png = dir / ("camera_preview" + x + ".png");  // not preview.png: the render's own preview may share the folder
  write_raw_tiff(o.raw_tiff, run.raw.dn, run.meta);
  write_raw_sidecar(o.raw_json, run.meta);
  const auto& rad = run.meta.extra.at("radiance");
  double lo = rad.at("band_lo_nm").front().get<double>(), hi = rad.at("band_hi_nm").back().get<double>();
  CameraColor sensor_color = camera_color(cam, lo, hi, false);
  if (opt.write_dng) {
    o.raw_dng = dir / ("raw" + x + ".dng");
    DngColor dc;
    dc.xyz_to_camera = sensor_color.xyz_to_camera;
    dc.as_shot_neutral = sensor_color.d65_neutral;
    write_dng(o.raw_dng, run.raw.dn, run.meta, dc);
  }
  write_electrons_exr(o.electrons_exr, run.expected,
                      {{"camera", cam.name}, {"radiance", rad.at("file")}, {"exposure_s", cam.sensor.exposure_s}});
  write_raw_preview_png(o.preview_png, run.raw.dn, run.meta.width, run.meta.height, run.meta.cfa,
                        run.meta.black_level_dn, run.meta.white_level_dn, sensor_color, opt.preview);
  return o;
}

}  // namespace ofl
