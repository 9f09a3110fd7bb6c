// `oralfluor chroma raw.tiff --roi x,y,w,h`: r,g chromaticity per 2x2 CFA cell of a raw mosaic
// written by `oralfluor camera`, ROI mean, covariance and 95 % ellipse, and a plot (SVG + PNG) with
// each library fluorophore's reference line (tongue reflectance + fluorophore under the scene's LED
// through this camera). See docs/camera.md.
#include <cstdio>
#include <fstream>
#include <sstream>

#include "renderer/core/files/atomic_file.h"
#include "renderer/analysis/chroma_plot.h"
#include "renderer/analysis/chroma_reference.h"
#include "renderer/analysis/chromaticity.h"
#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/optics/lens_optics.h"
#include "renderer/camera/raw/raw_writer.h"
#include "renderer/camera/optics/optics.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "renderer/spectral/spectrum_json.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {

// {"nm": [...], "W_per_sr_nm": [...]} (the renderer's oralfluor.excitation_spd) as a spectrum.
Spectrum spd_from_json(const JsonNode& n) {
  n.check_keys({"nm", "W_per_sr_nm"});
  auto nm = n.at("nm").numbers();
  auto v = n.at("W_per_sr_nm").numbers();
  if (nm.size() != v.size()) n.at("W_per_sr_nm").fail("has " + std::to_string(v.size()) + " values for " +
                                                     std::to_string(nm.size()) + " wavelengths");
  if (nm.size() < 2) n.at("nm").fail("needs at least two wavelengths");
  TabulatedSpectrum t;
  for (size_t i = 0; i < nm.size(); ++i) {
    if (i > 0 && !(nm[i] > nm[i - 1])) n.at("nm").at(i).fail("wavelengths must increase");
    if (!(v[i] >= 0)) n.at("W_per_sr_nm").at(i).fail("must be >= 0");
    t.nm.push_back(nm[i]);
    t.value.push_back(v[i]);
  }
  return table_spectrum(std::move(t), "LED");
}

// A spectrum named on the command line: a two-column CSV, or a JSON file holding either the
// renderer's {"nm", "W_per_sr_nm"} or any spectrum form of spectrum_json.h.
Spectrum spectrum_argument(const std::string& arg, const std::string& option, SpectrumKind kind) {
  std::filesystem::path p = arg;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) throw InputError(arg, option, "file not found");
  if (p.extension() == ".json") {
    JsonFile f = JsonFile::load(p);
    if (f.root().is_object() && f.root().has("W_per_sr_nm")) return spd_from_json(f.root());
    return parse_spectrum(f.root(), kind);
  }
  SpectrumCsvOptions o;
  o.outside = kind == SpectrumKind::kReflectance ? Outside::kClamp : Outside::kZero;
  return table_spectrum(read_spectrum_csv(p, o), p.filename().string());
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

// Pixels of the raw image that see scene material `name`, from the aov.material plane of the
// radiance EXR the camera was run on (named in the raw.json sidecar).
static std::vector<uint8_t> material_mask(const RawImage& raw, const std::string& raw_file, const std::string& name) {
  if (raw.sidecar.is_null() || !raw.sidecar.contains("radiance") || !raw.sidecar["radiance"].contains("file"))
    throw InputError(raw_file, "--roi-material", "raw.json does not name the radiance EXR");
  std::string exr = raw.sidecar["radiance"]["file"].get<std::string>();
  SpectralImage img = read_spectral_exr(exr);
  auto it = img.aovs.find("aov.material");
  if (it == img.aovs.end() || !img.attributes.count("oralfluor.materials"))
    throw InputError(exr, "--roi-material", "the radiance EXR has no aov.material plane (render it with oralfluor render)");
  std::vector<float> plane = it->second;
  if (img.width != raw.width || img.height != raw.height) {
    // The camera's optics stage gave the sensor its own grid: look the material up at each sensor
    // pixel's centre through the mapping raw.json records.
    const auto& sc = raw.sidecar;
    if (!sc.contains("optics") || !sc["optics"].contains("render_fov_on_sensor_px"))
      throw InputError(exr, "--roi-material", "the radiance EXR and the raw image differ in size");
    auto fov = sc["optics"]["render_fov_on_sensor_px"].get<std::vector<double>>();
    if (fov.size() != 4) throw InputError(raw_file, "optics/render_fov_on_sensor_px", "expected [x0, y0, x1, y1]");
    plane = render_plane_on_sensor(plane, img.width, img.height, raw.width, raw.height, fov, -1.0f);
  }
  nlohmann::json names;
  try {
    names = nlohmann::json::parse(img.attributes.at("oralfluor.materials"));
  } catch (const nlohmann::json::exception&) {
  }
  bool list = names.is_array();
  for (auto& n : names) list = list && n.is_string();
  if (!list) throw InputError(exr, "oralfluor.materials", "not a JSON list of material names");
  int index = -1;
  std::string have;
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) index = int(i);
    have += (have.empty() ? "" : ", ") + names[i].get<std::string>();
  }
  if (index < 0) throw InputError(exr, "--roi-material", "no material \"" + name + "\" in the scene (have: " + have + ")");
  std::vector<uint8_t> mask(plane.size());
  for (size_t i = 0; i < mask.size(); ++i) mask[i] = std::lround(plane[i]) == index;
  return mask;
}

namespace {

struct ChromaOptions {
  std::string raw, roi, out, led, reflectance, fluorophores, concentrations, name = "chroma", roi_material;
  double grid_step = 1.0;
  bool json = false, include_saturated = false;
};

// The cells of the ROI (and of the material, with --roi-material) and their statistics; warns when
// none is usable or saturated ones were left out.
ChromaStats measure_roi(const ChromaOptions& o, const RawImage& raw, const Roi& roi, std::vector<std::string>& warnings) {
  std::vector<uint8_t> mask;
  if (!o.roi_material.empty()) mask = material_mask(raw, o.raw, o.roi_material);
  ChromaStats stats;
  try {
    stats = roi_chromaticity(raw.dn, raw.width, raw.height, raw.meta.cfa, raw.meta.black_level_dn, raw.meta.white_level_dn, roi,
                             o.include_saturated, mask.empty() ? nullptr : &mask);
  } catch (const InputError& e) {
    throw InputError(o.raw, e.field(), e.what());
  }
  if (stats.used == 0) warnings.push_back("no usable cell in the ROI (all saturated or without signal)");
  if (stats.saturated && !o.include_saturated) warnings.push_back(std::to_string(stats.saturated) + " saturated cells left out");
  return stats;
}

// The LED spectrum: --led, else the radiance EXR's oralfluor.excitation_spd recorded in raw.json.
std::optional<Spectrum> led_spectrum(const ChromaOptions& o, const RawImage& raw, const std::optional<JsonFile>& side,
                                     std::string* source) {
  if (!o.led.empty()) {
    *source = o.led;
    return spectrum_argument(o.led, "--led", SpectrumKind::kEmission);
  }
  if (!side) return std::nullopt;
  auto attrs = side->root().find("exr_attributes");
  if (!attrs || !attrs->has("oralfluor.excitation_spd")) return std::nullopt;
  JsonNode a = attrs->at("oralfluor.excitation_spd");
  nlohmann::json parsed;
  try {
    parsed = nlohmann::json::parse(a.string());
  } catch (const std::exception&) {
    a.fail("not valid JSON");
  }
  JsonFile pf = JsonFile::from(parsed, raw.sidecar_file.string() + " /exr_attributes/oralfluor.excitation_spd");
  *source = "oralfluor.excitation_spd of the radiance EXR";
  return spd_from_json(pf.root());
}

// The reference computation's settings from raw.json: the camera's band and, since filters shift
// with angle, the ROI centre's field angle.
ReferenceOptions reference_options(const ChromaOptions& o, const RawImage& raw, const JsonFile& side, const Roi& roi) {
  ReferenceOptions ro;
  ro.step_nm = o.grid_step;
  if (auto rad = side.root().find("radiance")) {
    ro.camera_lo_nm = rad->at("band_lo_nm").at(0).number();
    auto hi = rad->at("band_hi_nm");
    ro.camera_hi_nm = hi.at(hi.size() - 1).number();
  }
  if (auto fg = side.root().find("field_geometry")) {
    FieldGeometry g;
    g.width = raw.width;
    g.height = raw.height;
    g.pixels_per_tan = fg->number_or("pixels_per_tan", 0.0, 0.0);
    g.sensor_tan_per_px = fg->number_or("sensor_tan_per_px", -1.0);
    double cx = roi.x + 0.5 * roi.w - 0.5 * raw.width, cy = roi.y + 0.5 * roi.h - 0.5 * raw.height;
    double r = std::sqrt(cx * cx + cy * cy);
    ro.aoi_front_rad = g.field_angle(r);
    ro.aoi_sensor_rad = g.sensor_angle(r);
  }
  return ro;
}

std::vector<double> parse_concentrations(const std::string& list) {
  std::vector<double> conc;
  for (auto& c : split_list(list)) {
    char* end = nullptr;
    double v = std::strtod(c.c_str(), &end);
    if (end == c.c_str() || *end != '\0' || !(v >= 0)) throw InputError("", "--concentrations", "not a concentration >= 0: \"" + c + "\"");
    conc.push_back(v);
  }
  return conc;
}

// Each fluorophore's reference line and what they were computed from ("reference" of the JSON).
struct References {
  std::vector<ReferenceLine> lines;
  nlohmann::json info = nlohmann::json::object();
};

// The reference lines need the camera (from the raw.json sidecar) and the LED; without either they
// are left out with a warning.
References reference_lines(const ChromaOptions& o, const RawImage& raw, const Roi& roi, std::vector<std::string>& warnings) {
  References refs;
  std::optional<JsonFile> side;
  if (!raw.sidecar.is_null()) side = JsonFile::from(raw.sidecar, raw.sidecar_file.string());
  std::string led_source;
  std::optional<Spectrum> led = led_spectrum(o, raw, side, &led_source);
  if (!side || !side->root().has("camera")) {
    warnings.push_back("no raw.json sidecar with the camera: reference lines left out");
    return refs;
  }
  if (!led) {
    warnings.push_back("no LED spectrum (the EXR had no oralfluor.excitation_spd): reference lines left out; give --led");
    return refs;
  }
  CameraDescription cam = parse_camera(side->root().at("camera"));
  Spectrum refl = o.reflectance.empty() ? tongue_reflectance_spectrum()
                                        : spectrum_argument(o.reflectance, "--reflectance", SpectrumKind::kReflectance);
  ReferenceOptions ro = reference_options(o, raw, *side, roi);
  ReferenceSetup setup = make_reference_setup(cam, *led, refl, ro);
  std::vector<double> conc = parse_concentrations(o.concentrations);
  std::vector<std::string> names = split_list(o.fluorophores);
  if (names.empty())
    for (auto& e : fluorophore_library()) names.push_back(e.name);
  for (auto& n : names) {
    GridEem eem = load_fluorophore(n, setup.grid, std::filesystem::current_path());
    refs.lines.push_back(reference_line(setup, n, eem, conc));
    if (!refs.lines.back().visible) warnings.push_back("fluorophore " + n + " gives no signal through this camera under this LED");
  }
  refs.info = {{"led", led_source},
               {"reflectance", o.reflectance.empty() ? asset_path("spectra/tissue/tongue_reflectance.csv").string() : o.reflectance},
               {"camera", cam.name},
               {"camera_range_nm", {ro.camera_lo_nm, ro.camera_hi_nm}},
               {"field_angle_deg", ro.aoi_front_rad * 180.0 / kPi},
               {"sensor_angle_deg", ro.aoi_sensor_rad * 180.0 / kPi},
               {"grid_nm", {setup.grid.min_nm, setup.grid.max_nm, setup.grid.step_nm}},
               {"tongue_rg", reference_rg(setup, nullptr, 0.0)}};
  return refs;
}

// --out, else the raw file's folder; created.
std::filesystem::path output_folder(const ChromaOptions& o) {
  std::filesystem::path dir = o.out.empty() ? std::filesystem::path(o.raw).parent_path() : std::filesystem::path(o.out);
  if (dir.empty()) dir = ".";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir, ec)) throw InputError(dir.string(), "", "cannot create output folder");
  return dir;
}

// The plot's title ("raw.tiff  ROI x,y,w,h seeing tongue: n cells, mean r, g") and subtitle.
ChromaPlotData plot_data(const ChromaOptions& o, const Roi& roi, const ChromaStats& stats, const References& refs) {
  ChromaPlotData plot;
  plot.stats = stats;
  plot.lines = refs.lines;
  char title[256];
  std::string where = o.roi_material.empty() ? "" : " seeing " + o.roi_material;
  std::snprintf(title, sizeof title, "%s  ROI %d,%d,%d,%d%s: %zu cells, mean r = %.4f, g = %.4f",
                std::filesystem::path(o.raw).filename().string().c_str(), roi.x, roi.y, roi.w, roi.h, where.c_str(), stats.used,
                stats.mean_r, stats.mean_g);
  plot.title = title;
  plot.subtitle = refs.lines.empty() ? "no reference lines"
                                     : "lines: tongue reflectance + increasing fluorophore concentration under the LED, "
                                       "through camera \"" + refs.info.value("camera", std::string()) + "\"";
  return plot;
}

// Writes the plot, the cells CSV and the JSON; returns the result with its "outputs".
nlohmann::json write_chroma_outputs(const ChromaOptions& o, const Roi& roi, const ChromaStats& stats, const References& refs,
                                    std::vector<std::string>& warnings) {
  std::filesystem::path dir = output_folder(o);
  auto stem = dir / o.name;
  if (!write_chroma_plot(plot_data(o, roi, stats, refs), stem))
    warnings.push_back("no TrueType font found: PNG written without labels (the SVG has them)");
  {
    std::ostringstream cells;
    cells << "r,g\n";
    cells.precision(9);
    for (auto& p : stats.rg) cells << p[0] << "," << p[1] << "\n";
    write_file_atomic(dir / (o.name + "_cells.csv"), cells.str());
  }
  nlohmann::json result = {{"raw", o.raw}, {"roi_material", o.roi_material}, {"stats", stats.to_json()}, {"reference", refs.info},
                           {"lines", nlohmann::json::array()}, {"warnings", warnings}};
  for (auto& l : refs.lines) result["lines"].push_back(l.to_json());
  auto jpath = stem;
  jpath += ".json";
  write_file_atomic(jpath, result.dump(1) + "\n");
  auto svg = stem, png = stem;
  svg += ".svg";
  png += ".png";
  result["outputs"] = {{"svg", svg.string()}, {"png", png.string()}, {"json", jpath.string()},
                       {"cells_csv", (dir / (o.name + "_cells.csv")).string()}};
  return result;
}

// The human-readable summary on stdout.
void print_chroma_summary(const ChromaOptions& o, const Roi& roi, const ChromaStats& stats, const References& refs,
                          const nlohmann::json& result) {
  std::string where = o.roi_material.empty() ? "" : " seeing " + o.roi_material;
  std::printf("ROI %d,%d,%d,%d%s of %s: %zu of %zu cells used (%zu saturated, %zu without signal)\n", roi.x, roi.y, roi.w, roi.h,
              where.c_str(), o.raw.c_str(), stats.used, stats.cells, stats.saturated, stats.nonpositive);
  std::printf("mean r = %.5f  g = %.5f   cov rr = %.3g rg = %.3g gg = %.3g\n", stats.mean_r, stats.mean_g, stats.cov_rr,
              stats.cov_rg, stats.cov_gg);
  std::printf("95%% ellipse: semi-axes %.4g, %.4g at %.1f deg\n", stats.ellipse95.a, stats.ellipse95.b,
              stats.ellipse95.angle_rad * 180.0 / kPi);
  for (auto& l : refs.lines)
    std::printf("  %-16s tongue (%.4f, %.4f) -> pure (%.4f, %.4f), equal-signal c = %.3g\n", l.fluorophore.c_str(), l.rg.front()[0],
                l.rg.front()[1], l.pure_rg[0], l.pure_rg[1], l.balance_concentration);
  const auto& f = result["outputs"];
  std::printf("wrote %s, %s, %s\n", f["svg"].get<std::string>().c_str(), f["png"].get<std::string>().c_str(),
              f["json"].get<std::string>().c_str());
}

void run_chroma(const ChromaOptions& o) {
  RawImage raw = read_raw(o.raw);
  Roi roi{0, 0, raw.width, raw.height};
  if (!o.roi.empty() && !parse_roi(o.roi, &roi))
    throw InputError("", "--roi", "expected x,y,w,h with w, h > 0 (got \"" + o.roi + "\")");
  std::vector<std::string> warnings;
  ChromaStats stats = measure_roi(o, raw, roi, warnings);
  References refs = reference_lines(o, raw, roi, warnings);
  nlohmann::json result = write_chroma_outputs(o, roi, stats, refs, warnings);
  for (auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (o.json) {
    std::printf("%s\n", result.dump(2).c_str());
    return;
  }
  print_chroma_summary(o, roi, stats, refs, result);
}

}  // namespace

void register_chroma_command(CLI::App& app) {
  auto o = std::make_shared<ChromaOptions>();
  auto* cmd = app.add_subcommand("chroma", "r,g chromaticity of a raw mosaic in a region, with fluorophore reference lines");
  cmd->add_option("raw", o->raw, "raw.tiff written by `oralfluor camera` (raw.json beside it)")->required();
  cmd->add_option("--roi", o->roi, "region x,y,w,h in pixels (default: the whole image)");
  cmd->add_option("--roi-material", o->roi_material,
                  "only cells that see this scene material (from the radiance EXR's aov.material plane)");
  cmd->add_option("-o,--out", o->out, "output folder (default: the raw file's folder)");
  cmd->add_option("--name", o->name, "output file stem (default: chroma)");
  cmd->add_option("--led", o->led, "LED spectrum (CSV, or JSON) when the raw.json has no oralfluor.excitation_spd");
  cmd->add_option("--reflectance", o->reflectance, "tissue reflectance (CSV or JSON; default: shipped tongue reflectance)");
  cmd->add_option("--fluorophores", o->fluorophores, "comma-separated library names or EEM files (default: the whole library)");
  cmd->add_option("--concentrations", o->concentrations, "comma-separated concentrations (default: automatic per fluorophore)");
  cmd->add_option("--grid-step", o->grid_step, "wavelength step of the reference-line computation, nm (default 1)")
      ->check(finite_range(0.1, 20.0));
  cmd->add_flag("--include-saturated", o->include_saturated, "keep cells with a value at the white level");
  cmd->add_flag("--json", o->json, "print the results as JSON");
  cmd->callback([o] { run_chroma(*o); });
}

}  // namespace ofl
