#include "renderer/sweep/sweep_point.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include "renderer/analysis/chroma_reference.h"
#include "renderer/analysis/chromaticity.h"
#include "renderer/analysis/fluorescence_chart.h"
#include "renderer/camera/camera_pipeline.h"
#include "renderer/camera/raw/camera_color.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/file_dependencies.h"
#include "renderer/image/png_writer.h"
#include "renderer/render/render_job.h"
#include "renderer/spectral/chromophores/fluorophore_library.h"
#include "renderer/sweep/design/rig_generators.h"
#include "renderer/sweep/metrics/signal_split.h"
#include "renderer/sweep/metrics/sweep_metrics.h"
#include "renderer/sweep/metrics/sweep_plots.h"
#include "renderer/sweep/store/render_cache.h"

namespace ofl {
namespace {

uint64_t fnv1a(const std::string& s, uint64_t h = 0xcbf29ce484222325ULL) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string canonical_text(const std::filesystem::path& p) {
  std::error_code ec;
  auto c = std::filesystem::weakly_canonical(p, ec);
  return ec ? p.string() : c.string();
}

std::string hex16(uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

double round_to(double v, double q) { return std::round(v / q) * q; }

// Box-filtered downscale of linear RGB.
std::vector<float> downscale(const std::vector<float>& rgb, int w, int h, int tw, int th) {
  std::vector<float> out(size_t(tw) * th * 3, 0.0f);
  for (int ty = 0; ty < th; ++ty)
    for (int tx = 0; tx < tw; ++tx) {
      int x0 = tx * w / tw, x1 = std::max(x0 + 1, (tx + 1) * w / tw);
      int y0 = ty * h / th, y1 = std::max(y0 + 1, (ty + 1) * h / th);
      double s[3] = {0, 0, 0};
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
          for (int c = 0; c < 3; ++c) s[c] += rgb[(size_t(y) * w + x) * 3 + c];
      double n = double(x1 - x0) * (y1 - y0);
      for (int c = 0; c < 3; ++c) out[(size_t(ty) * tw + tx) * 3 + c] = float(s[c] / n);
    }
  return out;
}

// A PNG (bytes) of linear RGB scaled to `width` pixels wide; exposure < 0: automatic.
std::string thumbnail_png(const std::vector<float>& rgb, int w, int h, int width, double exposure = -1) {
  int tw = std::min(width, w), th = std::max(1, int(std::lround(double(h) * tw / w)));
  std::vector<float> small = downscale(rgb, w, h, tw, th);
  return srgb_png_bytes(tw, th, small, exposure > 0 ? exposure : auto_exposure(small));
}

// Which of the base files a point uses (a scene_file / camera_file parameter may pick another).
std::pair<std::filesystem::path, std::filesystem::path> point_files(const SweepSpec& spec, const DesignPoint& pt) {
  auto scene = spec.scene, camera = spec.camera;
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const auto& p = spec.parameters[i];
    if (p.kind != ParamKind::kGenerator || !pt.values[i].is_string()) continue;
    std::filesystem::path v = pt.values[i].get<std::string>();
    if (v.is_relative()) v = std::filesystem::path(spec.file).parent_path() / v;
    if (p.generator == "scene_file") scene = v;
    if (p.generator == "camera_file") camera = v;
  }
  return {scene, camera};
}

const std::vector<std::string> kReferenceFluorophores = {"FAD", "NADH", "collagen", "protoporphyrin"};

}  // namespace

std::string base64_encode(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    out += t[v >> 18];
    out += t[(v >> 12) & 63];
    out += t[(v >> 6) & 63];
    out += t[v & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t v = uint8_t(in[i]) << 16;
    out += t[v >> 18];
    out += t[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
    out += t[v >> 18];
    out += t[(v >> 12) & 63];
    out += t[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string base64_decode(const std::string& in) {
  std::string out;
  uint32_t acc = 0;
  int bits = 0;
  for (char ch : in) {
    int v = ch >= 'A' && ch <= 'Z' ? ch - 'A' : ch >= 'a' && ch <= 'z' ? ch - 'a' + 26 : ch >= '0' && ch <= '9' ? ch - '0' + 52
          : ch == '+' ? 62 : ch == '/' ? 63 : -1;
    if (v < 0) continue;
    acc = (acc << 6) | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((acc >> bits) & 0xff);
    }
  }
  return out;
}

namespace {

// The point's own part of its identity: each parameter's value and what it edits.
nlohmann::json identity_parameters(const SweepSpec& spec, const DesignPoint& pt) {
  nlohmann::json params = nlohmann::json::array();
  for (size_t i = 0; i < spec.parameters.size(); ++i) {
    const auto& p = spec.parameters[i];
    nlohmann::json j = {{"name", p.name}, {"value", pt.values[i]}};
    describe_target(p, j);
    switch (p.kind) {
      case ParamKind::kScenePath:
      case ParamKind::kCameraPath:
      case ParamKind::kGenerator: break;
      case ParamKind::kVariants:
        for (auto& v : p.variants)
          if (v.label == pt.values[i]) {
            nlohmann::json e = nlohmann::json::array();
            for (auto& [k, x] : v.scene_edits) e.push_back({"scene", k, x});
            for (auto& [k, x] : v.camera_edits) e.push_back({"camera", k, x});
            j["edits"] = e;
          }
        break;
    }
    params.push_back(j);
  }
  return params;
}

// What every point of the sweep shares: its render, camera and metric settings and its ROIs.
nlohmann::json identity_settings(const SweepSpec& spec) {
  nlohmann::json full = spec.to_json();
  full["render"].erase("cache");  // where the render comes from does not change the result
  nlohmann::json rois = full["rois"];
  for (auto& r : rois)
    for (auto& t : r["textures"]) t["file"] = canonical_text(t["file"].get<std::string>());
  return {{"render", full["render"]}, {"camera_run", full["camera_run"]}, {"rois", rois}, {"metrics", full["metrics"]}};
}

// Bump identity_version whenever what a point computes changes, so old results are not reused
// (3: output bands default to the whole grid).
nlohmann::json assemble_identity(const nlohmann::json& settings, const std::string& scene, const std::string& scene_hash,
                                 const std::string& camera, const std::string& camera_hash, nlohmann::json params) {
  nlohmann::json id = settings;
  id["identity_version"] = 3;
  id["scene"] = scene;
  id["scene_text"] = scene_hash;
  id["camera"] = camera;
  id["camera_text"] = camera_hash;
  id["parameters"] = std::move(params);
  return id;
}

}  // namespace

nlohmann::json point_identity(const SweepSpec& spec, const DesignPoint& pt) {
  auto [scene, camera] = point_files(spec, pt);
  return assemble_identity(identity_settings(spec), canonical_text(scene), hex16(fnv1a(slurp(scene))), canonical_text(camera),
                           hex16(fnv1a(slurp(camera))), identity_parameters(spec, pt));
}

std::string point_key(const SweepSpec& spec, const DesignPoint& pt) { return hex16(fnv1a(point_identity(spec, pt).dump())); }

PointKeys::PointKeys(const SweepSpec& spec) : spec_(spec), shared_(identity_settings(spec)) {}

std::string PointKeys::key(const DesignPoint& pt) {
  auto [scene, camera] = point_files(spec_, pt);
  auto file = [&](const std::filesystem::path& f) -> const std::pair<std::string, std::string>& {
    auto it = files_.find(f.string());
    if (it == files_.end()) it = files_.emplace(f.string(), std::make_pair(canonical_text(f), hex16(fnv1a(slurp(f))))).first;
    return it->second;
  };
  // The identity's text is the same for every point up to its "parameters" (objects dump their
  // members sorted by name) and after them: hash the prefix once per pair of base files, then
  // continue with this point's parameters and the suffix. FNV-1a is a running hash, so the key is
  // exactly point_key's.
  const auto& [scene_name, scene_hash] = file(scene);
  const auto& [camera_name, camera_hash] = file(camera);
  const std::string pair = scene_name + '\n' + camera_name;
  auto it = frames_.find(pair);
  if (it == frames_.end()) {
    static const std::string kMark = "\x01parameters\x01";
    std::string text = assemble_identity(shared_, scene_name, scene_hash, camera_name, camera_hash, kMark).dump();
    const std::string mark = nlohmann::json(kMark).dump();
    const size_t at = text.find(mark);
    it = frames_.emplace(pair, Frame{fnv1a(text.substr(0, at)), text.substr(at + mark.size())}).first;
  }
  return hex16(fnv1a(it->second.suffix, fnv1a(identity_parameters(spec_, pt).dump(), it->second.prefix_hash)));
}

LoadedPoint load_point(const SweepSpec& spec, const DesignPoint& pt) {
  const std::string label = point_label(spec, pt);
  PointDocuments docs = point_documents(spec, pt.values);

  if (!docs.scene.is_object()) throw InputError(docs.scene_file.string(), "", "a scene must be a JSON object");
  // Render settings of the sweep go into the scene document (the CLI's overrides for the rest).
  nlohmann::json& integ = docs.scene["integrator"];
  if (!integ.is_object()) integ = nlohmann::json::object();
  if (spec.render.noise_target) integ["noise_target"] = *spec.render.noise_target;
  if (spec.render.max_depth) integ["max_depth"] = *spec.render.max_depth;
  if (spec.render.output_bands) integ["output_bands"] = *spec.render.output_bands;
  SceneOverrides ov;
  ov.spp = spec.render.spp;
  ov.seed = spec.render.seed;
  ov.width = spec.render.width;
  ov.height = spec.render.height;
  LoadedPoint lp;
  try {
    {
      FileDependencyRecorder r;
      lp.scene = load_scene(JsonFile::from(docs.scene, docs.scene_file.string()), ov);
      // The camera whose response steers the wavelength sampling is read by the renderer: its
      // QE and filter files are inputs of the render too.
      if (!lp.scene.integrator.importance_camera.empty()) load_camera(lp.scene.integrator.importance_camera);
      lp.scene_inputs = r.files();
    }
    lp.camera = parse_camera(JsonFile::from(docs.camera, docs.camera_file.string()).root());
    lp.camera.source = docs.camera_file.string();
  } catch (const InputError& e) {
    // The edited documents broke: the sweep file is what the user changes. Name the parameter
    // whose pointer reaches the rejected field when there is one, else the parameters as a whole.
    const bool in_camera = e.file() == docs.camera_file.string();
    std::string where = "/parameters";
    for (size_t i = 0; i < spec.parameters.size(); ++i) {
      const auto& p = spec.parameters[i];
      if (p.kind != (in_camera ? ParamKind::kCameraPath : ParamKind::kScenePath) || p.pointer.empty()) continue;
      const std::string& f = e.field();
      if (f.rfind(p.pointer, 0) == 0 || p.pointer.rfind(f, 0) == 0) { where = p.where; break; }
    }
    throw InputError(spec.file, where,
                     "sweep point " + std::to_string(pt.index) + " (" + label + ") makes " + e.describe());
  }
  lp.docs = std::move(docs);
  lp.overrides = ov;
  return lp;
}

namespace {

// The point's renders: one, or two with independent seeds whose average is analysed
// (spec.render.replicates); the halves stay for the Monte Carlo noise of the metrics.
struct PointRenders {
  RenderResult result;           // the image analysed (the average of both when there are two)
  SpectralImage half_a, half_b;  // the two replicates (empty with one)
  RenderStats stats;             // of the image analysed
  double seconds = 0;            // spent on the renders by this point (reading them when cached)
  std::string key_a, key_b;      // render cache keys
  bool cached_a = false, cached_b = false;
};

// One render of the point, or the one another point of this sweep made of the same scene with the
// same settings (render_cache.h): points that differ only in camera fields render once. Empty when
// interrupted.
std::optional<RenderResult> obtain_render(const LoadedPoint& lp, const Scene& scene, PointRunContext& ctx, int replicate,
                                          const RenderOptions& o, std::string* rkey, bool* cached, double* seconds) {
  auto t = std::chrono::steady_clock::now();
  nlohmann::json id = render_identity(lp.docs.scene, lp.docs.scene_file.parent_path(), lp.scene_inputs, lp.overrides, replicate);
  *rkey = render_key(id);
  *cached = false;
  std::optional<RenderResult> out;
  if (ctx.render_cache) {
    std::string damaged;
    if (auto c = ctx.render_cache->load(*rkey, &damaged)) {
      out = RenderResult{std::move(c->image), c->stats};
      *cached = true;
    } else if (!damaged.empty()) {
      std::fprintf(stderr, "warning: %s\n", damaged.c_str());
    }
  }
  if (!out) {
    out = render(scene, o);
    if (out->stats.interrupted) return std::nullopt;
    if (ctx.render_cache) ctx.render_cache->save(*rkey, id, out->image, out->stats);
  }
  *seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
  return out;
}

// The first render and, with two replicates, a second (another seed) averaged into it, weighted by
// the sample counts. Empty when interrupted.
std::optional<PointRenders> render_point(const SweepSpec& spec, LoadedPoint& lp, PointRunContext& ctx) {
  Scene& scene = lp.scene;
  PointRenders pr;
  RenderOptions ro;
  ro.progress = ctx.progress;
  std::optional<RenderResult> first = obtain_render(lp, scene, ctx, 0, ro, &pr.key_a, &pr.cached_a, &pr.seconds);
  if (!first) return std::nullopt;
  pr.result = std::move(*first);
  RenderResult& rr = pr.result;
  pr.stats = rr.stats;
  if (spec.render.replicates != 2) return pr;
  const uint64_t seed = scene.integrator.seed;
  scene.integrator.seed = seed + 0x9e3779b97f4a7c15ULL;
  RenderOptions ro2 = ro;
  ro2.aovs = false;
  std::optional<RenderResult> second = obtain_render(lp, scene, ctx, 1, ro2, &pr.key_b, &pr.cached_b, &pr.seconds);
  scene.integrator.seed = seed;
  if (!second) return std::nullopt;
  const RenderResult& rb = *second;
  pr.half_a = rr.image;
  pr.half_b = rb.image;
  const SpectralImage &half_a = pr.half_a, &half_b = pr.half_b;
  double wa = rr.stats.spp_done, wb = rb.stats.spp_done, ws = wa + wb;
  for (size_t i = 0; i < rr.image.data.size(); ++i) rr.image.data[i] = float((wa * half_a.data[i] + wb * half_b.data[i]) / ws);
  for (size_t i = 0; i < rr.image.fluorescence.size() && i < half_b.fluorescence.size(); ++i)
    rr.image.fluorescence[i] = float((wa * half_a.fluorescence[i] + wb * half_b.fluorescence[i]) / ws);
  pr.stats.spp_done += rb.stats.spp_done;
  pr.stats.seconds += rb.stats.seconds;
  // Per-pixel noise of the average of two independent estimates.
  pr.stats.relative_noise = 0.5 * std::sqrt(rr.stats.relative_noise * rr.stats.relative_noise +
                                            rb.stats.relative_noise * rb.stats.relative_noise);
  return pr;
}

// The LEDs' summed spectrum, the output bands inside their emission band (leaked excitation is
// reflected light there) and those bands merged into [lo, hi] runs for the result.
struct LedBands {
  std::vector<double> led;  // on the scene's grid
  std::vector<bool> in_band;
  nlohmann::json runs = nlohmann::json::array();
};
LedBands led_bands(const Scene& scene, const SpectralImage& img, double threshold) {
  LedBands lb;
  const WavelengthGrid& grid = scene.grid();
  lb.led.assign(grid.size(), 0.0);
  for (const auto& l : scene.lights)
    for (int i = 0; i < grid.size(); ++i) lb.led[i] += l.spectral_intensity[i];
  auto lo = img.band_lo(), hi = img.band_hi();
  lb.in_band = led_band_mask(lo, hi, grid, lb.led, threshold);
  for (size_t b = 0; b < lb.in_band.size(); ++b)
    if (lb.in_band[b]) {
      if (!lb.runs.empty() && lb.runs.back()[1] == lo[b]) lb.runs.back()[1] = hi[b];
      else lb.runs.push_back({lo[b], hi[b]});
    }
  return lb;
}

// What the metrics read (sweep_metrics.h), with the planes computed here kept alive beside it.
struct MetricInputs {
  MetricImages images;
  SignalSplit split;
  std::vector<float> ch_a, ch_b;  // expected electrons per channel of each replicate
  std::vector<float> field_angle_deg;
};
// Fills `in` in place (its images point into its own vectors).
void fill_metric_inputs(MetricInputs& in, const PointRenders& pr, const CameraRun& run, const CameraDescription& cam,
                        const std::vector<bool>& in_band, bool replicates) {
  const SpectralImage& img = pr.result.image;
  const int W = img.width, H = img.height;
  in.split = split_signal(img, in_band, cam, run.geometry);
  MetricImages& mi = in.images;
  mi.width = W;
  mi.height = H;
  mi.cfa = run.meta.cfa;
  mi.black = run.meta.black_level_dn;
  mi.white = run.meta.white_level_dn;
  mi.raw = &run.raw.dn;
  mi.expected = &run.expected.mosaic_e;
  mi.channel_e = &run.expected.channel_e;
  if (replicates) {
    in.ch_a = expected_electrons(pr.half_a, cam, run.geometry).channel_e;
    in.ch_b = expected_electrons(pr.half_b, cam, run.geometry).channel_e;
    mi.channel_e_a = &in.ch_a;
    mi.channel_e_b = &in.ch_b;
  }
  mi.irradiance = &img.aovs.at("aov.irradiance");
  in.field_angle_deg.resize(size_t(W) * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      in.field_angle_deg[size_t(y) * W + x] =
          float(run.geometry.field_angle(run.geometry.radius_px(x, y)) * 180.0 / 3.14159265358979323846);
  mi.field_angle_deg = &in.field_angle_deg;
  mi.fluorescence = &in.split.fluorescence;
  mi.reflected = &in.split.reflected;
  mi.leak = &in.split.leak;
}

// The pixels one ROI holds: its material, and inside every texture window.
struct RoiMask {
  std::vector<uint8_t> mask;
  size_t pixels = 0;
  double x_sum = 0, y_sum = 0;  // of the pixels' indices, for the centroid
};
RoiMask roi_mask(const RoiSpec& roi, int material, const SpectralImage& img, PointRunContext& ctx) {
  const auto& mat = img.aovs.at("aov.material");
  const auto& au = img.aovs.at("aov.u");
  const auto& av = img.aovs.at("aov.v");
  std::vector<const Texture*> tex;
  for (auto& c : roi.textures) {
    auto it = ctx.textures.find(c.file.string());
    if (it == ctx.textures.end()) it = ctx.textures.emplace(c.file.string(), read_texture(c.file)).first;
    tex.push_back(&it->second);
  }
  RoiMask m;
  m.mask.assign(size_t(img.width) * img.height, 0);
  for (size_t i = 0; i < m.mask.size(); ++i) {
    if (material < 0 || std::lround(mat[i]) != material) continue;
    bool inside = true;
    for (size_t k = 0; k < tex.size() && inside; ++k) {
      double t = tex[k]->lookup(au[i], av[i]);
      inside = t > roi.textures[k].above && t < roi.textures[k].below;
    }
    if (!inside) continue;
    m.mask[i] = 1;
    ++m.pixels;
    m.x_sum += double(i % img.width);
    m.y_sum += double(i / img.width);
  }
  return m;
}

// What the report draws of one ROI: a subsample of the cells, the mean and the 95 % ellipse, from
// the raw and from the noise-free cells.
nlohmann::json roi_scatter(const RoiCells& rc, int scatter_cells) {
  size_t keep = size_t(std::max(0, scatter_cells));
  size_t stride = keep ? std::max<size_t>(1, (rc.cells.size() + keep - 1) / keep) : 0;
  nlohmann::json s = nlohmann::json::object();
  for (bool nf : {false, true}) {
    const std::string suffix = nf ? "_nf" : "";
    nlohmann::json pts = nlohmann::json::array();
    for (size_t k = 0; stride && k < rc.cells.size(); k += stride) {
      const auto& rg = nf ? rc.cells[k].rg_nf : rc.cells[k].rg;
      pts.push_back({round_to(rg[0], 1e-5), round_to(rg[1], 1e-5)});
    }
    s["cells" + suffix] = pts;
    if (rc.cells.size() >= 2) {
      std::vector<std::array<double, 2>> rg;
      for (auto& c : rc.cells) rg.push_back(nf ? c.rg_nf : c.rg);
      Spread sp = chroma_spread(rg);
      Ellipse e = covariance_ellipse(sp.mean_r, sp.mean_g, sp.cov_rr, sp.cov_rg, sp.cov_gg);
      s["mean" + suffix] = {sp.mean_r, sp.mean_g};
      s["ellipse" + suffix] = {{"a", e.a}, {"b", e.b}, {"angle_rad", e.angle_rad}};
    }
  }
  return s;
}

// Every ROI's metrics and scatter, the lesion contrast, which ROI each pixel shows in the ROI
// picture, and the first ROI's centroid (where the reference lines are evaluated).
struct RoiResults {
  nlohmann::ordered_json metrics;
  nlohmann::json scatter = nlohmann::json::object();
  std::vector<int> roi_of_pixel;  // last ROI a pixel belongs to, -1 for none
  double cx_sum = 0, cy_sum = 0, c_n = 0;
};
RoiResults measure_rois(const SweepSpec& spec, const Scene& scene, const SpectralImage& img, const MetricImages& mi,
                        const CameraDescription& cam, PointRunContext& ctx, std::vector<std::string>& warnings) {
  RoiResults r;
  std::map<std::string, RoiCells> cells;
  r.roi_of_pixel.assign(size_t(img.width) * img.height, -1);
  for (const auto& roi : spec.rois) {
    int index = -1;
    for (size_t m = 0; m < scene.materials.size(); ++m)
      if (scene.materials[m].name == roi.material) index = int(m);
    if (index < 0) warnings.push_back("ROI " + roi.name + ": the scene has no material \"" + roi.material + "\"");
    RoiMask m = roi_mask(roi, index, img, ctx);
    if (&roi == &spec.rois.front()) {
      r.cx_sum = m.x_sum;
      r.cy_sum = m.y_sum;
      r.c_n = double(m.pixels);
    }
    if (index >= 0 && m.pixels == 0) warnings.push_back("ROI " + roi.name + " covers no pixel");
    RoiCells rc;
    nlohmann::ordered_json rm = roi_metrics(mi, m.mask, cam.sensor, &rc);
    for (auto it = rm.begin(); it != rm.end(); ++it) r.metrics[roi.name + "." + it.key()] = it.value();
    r.scatter[roi.name] = roi_scatter(rc, spec.metrics.scatter_cells);
    cells[roi.name] = std::move(rc);
    for (size_t i = 0; i < m.mask.size(); ++i)
      if (m.mask[i]) r.roi_of_pixel[i] = int(&roi - spec.rois.data());
  }
  if (!spec.metrics.lesion_roi.empty()) {
    nlohmann::ordered_json c = contrast_metrics(cells[spec.metrics.lesion_roi], cells[spec.metrics.healthy_roi]);
    for (auto it = c.begin(); it != c.end(); ++it) r.metrics["contrast." + it.key()] = it.value();
  }
  return r;
}

// Fluorophore reference lines for this point's LED and camera, at the first ROI's field angle:
// {"tongue_rg", "lines"} of the result's "reference".
nlohmann::ordered_json reference_json(const Scene& scene, const std::vector<double>& led, const SpectralImage& img,
                              const CameraDescription& cam, const FieldGeometry& geometry, const RoiResults& rois) {
  const WavelengthGrid& grid = scene.grid();
  nlohmann::json lines = nlohmann::json::array();
  nlohmann::json tongue_rg = nullptr;
  TabulatedSpectrum t;
  for (int i = 0; i < grid.size(); ++i) {
    t.nm.push_back(grid.wavelength(i));
    t.value.push_back(led[i]);
  }
  ReferenceOptions o;
  o.camera_lo_nm = img.band_lo().front();
  o.camera_hi_nm = img.band_hi().back();
  if (rois.c_n > 0) {
    double dx = rois.cx_sum / rois.c_n + 0.5 - 0.5 * img.width, dy = rois.cy_sum / rois.c_n + 0.5 - 0.5 * img.height;
    double r = std::sqrt(dx * dx + dy * dy);
    o.aoi_front_rad = geometry.field_angle(r);
    o.aoi_sensor_rad = geometry.sensor_angle(r);
  }
  ReferenceSetup setup = make_reference_setup(cam, table_spectrum(t, "LED"), tongue_reflectance_spectrum(), o);
  auto trg = reference_rg(setup, nullptr, 0.0);
  if (std::isfinite(trg[0])) tongue_rg = {trg[0], trg[1]};
  for (const auto& name : kReferenceFluorophores) {
    GridEem eem = load_fluorophore(name, setup.grid);
    ReferenceLine l = reference_line(setup, name, eem);
    if (!l.visible) continue;
    nlohmann::json rg = nlohmann::json::array();
    for (auto& p : l.rg) rg.push_back({round_to(p[0], 1e-5), round_to(p[1], 1e-5)});
    lines.push_back({{"fluorophore", name}, {"rg", rg}});
  }
  return nlohmann::ordered_json{{"tongue_rg", tongue_rg}, {"lines", lines}};
}

// The point's two pictures as PNG bytes: the camera preview, and the ROIs over a grey version of
// it so that a user can see what each ROI holds.
struct PointPictures {
  std::string preview_png, roi_png;
};
PointPictures point_pictures(const CameraRun& run, const CameraDescription& cam, const SpectralImage& img,
                             const std::vector<int>& roi_of_pixel, int thumbnail_width) {
  const int W = img.width, H = img.height;
  CameraColor color = camera_color(cam, img.band_lo().front(), img.band_hi().back(), false);
  std::vector<float> rgb = raw_to_linear_srgb(run.raw.dn, W, H, run.meta.cfa, run.meta.black_level_dn,
                                              run.meta.white_level_dn, color, PreviewSettings{});
  PointPictures p;
  p.preview_png = thumbnail_png(rgb, W, H, thumbnail_width);
  std::vector<float> roi_rgb(rgb.size());
  double ex = auto_exposure(rgb);
  for (size_t i = 0; i < roi_of_pixel.size(); ++i) {
    float grey = float(std::min(1.0, ex * (0.2126 * rgb[i * 3] + 0.7152 * rgb[i * 3 + 1] + 0.0722 * rgb[i * 3 + 2])));
    float c[3] = {grey, grey, grey};
    if (roi_of_pixel[i] >= 0) {
      Rgba col = roi_color(size_t(roi_of_pixel[i]));
      float lin[3] = {std::pow(col.r, 2.2f), std::pow(col.g, 2.2f), std::pow(col.b, 2.2f)};
      for (int k = 0; k < 3; ++k) c[k] = 0.35f * grey + 0.65f * lin[k];
    }
    for (int k = 0; k < 3; ++k) roi_rgb[i * 3 + k] = c[k];
  }
  p.roi_png = thumbnail_png(roi_rgb, W, H, std::max(W, thumbnail_width), 1.0);
  return p;
}

// The result's "render" member: size, samples, noise, time and the light outside the bands.
nlohmann::ordered_json render_summary(const SweepSpec& spec, const Scene& scene, const PointRenders& pr) {
  const SpectralImage& img = pr.result.image;
  return {{"width", img.width},
          {"height", img.height},
          {"spp", pr.stats.spp_done},
          {"replicates", spec.render.replicates},
          {"spp_max", scene.integrator.spp},
          {"noise_target", scene.integrator.noise_target},
          {"relative_noise", pr.stats.relative_noise},
          {"seconds", pr.seconds},
          {"lights", scene.lights.size()},
          {"bands_nm", {img.band_lo().front(), img.band_hi().back()}},
          {"led_power_outside_bands", led_light_outside_bands(scene).outside_share}};
}

}  // namespace

PointOutcome evaluate_point(const SweepSpec& spec, const DesignPoint& pt, PointRunContext& ctx) {
  auto t0 = std::chrono::steady_clock::now();
  const std::string key = point_key(spec, pt), label = point_label(spec, pt);
  LoadedPoint lp = load_point(spec, pt);
  const Scene& scene = lp.scene;
  const CameraDescription& cam = lp.camera;
  std::optional<PointRenders> renders = render_point(spec, lp, ctx);
  if (!renders) return {{}, true};
  const SpectralImage& img = renders->result.image;

  CameraRunOptions co;
  co.noise = spec.camera_run.noise;
  co.seed = spec.camera_run.seed;
  co.write_dng = false;
  CameraRun run = simulate_camera(img, cam, co, "sweep point " + key);
  LedBands bands = led_bands(scene, img, spec.metrics.led_band_threshold);
  MetricInputs inputs;
  fill_metric_inputs(inputs, *renders, run, cam, bands.in_band, spec.render.replicates == 2);
  std::vector<std::string> warnings = run.warnings;
  RoiResults rois = measure_rois(spec, scene, img, inputs.images, cam, ctx, warnings);
  nlohmann::ordered_json reference = reference_json(scene, bands.led, img, cam, run.geometry, rois);
  PointPictures pictures = point_pictures(run, cam, img, rois.roi_of_pixel, spec.report.thumbnail_width);

  nlohmann::ordered_json params;
  for (size_t i = 0; i < spec.parameters.size(); ++i) params[spec.parameters[i].name] = pt.values[i];
  char host[256] = "";
  ::gethostname(host, sizeof host - 1);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  nlohmann::ordered_json res;
  res["format"] = "oralfluor-sweep-point";
  res["version"] = 1;
  res["key"] = key;
  res["index"] = pt.index;
  res["label"] = label;
  res["parameters"] = params;
  res["metrics"] = rois.metrics;
  res["render"] = render_summary(spec, scene, *renders);
  res["render_cached"] = renders->cached_a && (spec.render.replicates < 2 || renders->cached_b);
  res["render_key"] = renders->key_a;
  if (spec.render.replicates == 2) res["render_key_2"] = renders->key_b;
  res["camera"] = {{"name", cam.name}, {"saturated_fraction", run.summary["saturated_fraction"]}};
  res["led_band_nm"] = bands.runs;
  res["scatter"] = rois.scatter;
  res["reference"] = reference;
  res["thumbnail_png_base64"] = base64_encode(pictures.preview_png);
  res["roi_png_base64"] = base64_encode(pictures.roi_png);
  res["warnings"] = warnings;
  res["identity"] = point_identity(spec, pt);
  res["host"] = host;
  res["rank"] = ctx.rank;
  res["seconds"] = seconds;
  return {std::move(res), false};
}

}  // namespace ofl
