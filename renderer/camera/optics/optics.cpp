#include "renderer/camera/optics/optics.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/optics/lens_optics.h"
#include "renderer/camera/elements/psf.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/process/progress.h"
#include "renderer/core/process/memory_limit.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

// ---- geometry and resampling --------------------------------------------------------------

double image_distance_mm(const LensDescription& lens, const OpticsDescription& o) {
  double f = lens.focal_length_mm;
  if (o.focus_distance_mm > 0) return f * o.focus_distance_mm / (o.focus_distance_mm - f);
  return f * (1.0 - lens.magnification);
}

RenderOnSensor map_render_to_sensor(int W, int H, double vfov_deg, double v_mm, double pitch_um,
                                    const OpticsDescription& o) {
  RenderOnSensor m;
  m.render_pitch_um = v_mm * 1000.0 * 2.0 * std::tan(0.5 * vfov_deg * kPi / 180.0) / H;
  m.scale = m.render_pitch_um / pitch_um;
  // Render edge i at x = (i - W / 2) p_r from the axis; sensor coordinate u = (x - offset) / p + Ws / 2.
  m.x0 = (-0.5 * W * m.render_pitch_um - o.offset_x_um) / pitch_um + 0.5 * o.sensor_width_px;
  m.y0 = (-0.5 * H * m.render_pitch_um - o.offset_y_um) / pitch_um + 0.5 * o.sensor_height_px;
  return m;
}

double OverlapWeights::coverage(int I) const {
  double s = 0;
  for (double v : w[I]) s += v;
  return s;
}

OverlapWeights overlap_weights(int render_n, int sensor_n, double x0, double s) {
  OverlapWeights ow;
  ow.first.assign(sensor_n, 0);
  ow.w.resize(sensor_n);
  for (int I = 0; I < sensor_n; ++I) {
    int lo = std::max(0, static_cast<int>(std::floor((I - x0) / s)));
    int hi = std::min(render_n - 1, static_cast<int>(std::ceil((I + 1 - x0) / s)));
    ow.first[I] = lo;
    for (int i = lo; i <= hi; ++i) {
      double a = std::max<double>(I, x0 + s * i), b = std::min<double>(I + 1, x0 + s * (i + 1));
      ow.w[I].push_back(std::max(0.0, b - a));
    }
  }
  return ow;
}

SpectralImage resample_to_sensor(const SpectralImage& img, int Ws, int Hs, const RenderOnSensor& m,
                                 std::vector<float>* coverage) {
  OverlapWeights wx = overlap_weights(img.width, Ws, m.x0, m.scale);
  OverlapWeights wy = overlap_weights(img.height, Hs, m.y0, m.scale);
  const int nb = img.bands();
  SpectralImage out;
  out.resize(Ws, Hs, img.band_nm);
  out.attributes = img.attributes;
  // Pass 1: along x, every render row -> Ws columns.
  std::vector<float> rows(static_cast<size_t>(Ws) * img.height * nb, 0.0f);
  tbb::parallel_for(0, img.height, [&](int j) {
    std::vector<double> acc(nb);
    for (int I = 0; I < Ws; ++I) {
      std::fill(acc.begin(), acc.end(), 0.0);
      for (size_t k = 0; k < wx.w[I].size(); ++k) {
        const float* L = img.pixel(wx.first[I] + static_cast<int>(k), j);
        for (int b = 0; b < nb; ++b) acc[b] += wx.w[I][k] * L[b];
      }
      float* o = rows.data() + (static_cast<size_t>(j) * Ws + I) * nb;
      for (int b = 0; b < nb; ++b) o[b] = static_cast<float>(acc[b]);
    }
  });
  // Pass 2: along y.
  tbb::parallel_for(0, Hs, [&](int J) {
    std::vector<double> acc(static_cast<size_t>(Ws) * nb, 0.0);
    for (size_t k = 0; k < wy.w[J].size(); ++k) {
      const float* r = rows.data() + static_cast<size_t>(wy.first[J] + k) * Ws * nb;
      double w = wy.w[J][k];
      for (size_t i = 0; i < acc.size(); ++i) acc[i] += w * r[i];
    }
    for (int I = 0; I < Ws; ++I)
      for (int b = 0; b < nb; ++b) out.pixel(I, J)[b] = static_cast<float>(acc[static_cast<size_t>(I) * nb + b]);
  });
  if (coverage) {
    coverage->assign(static_cast<size_t>(Ws) * Hs, 0.0f);
    for (int J = 0; J < Hs; ++J)
      for (int I = 0; I < Ws; ++I)
        (*coverage)[static_cast<size_t>(J) * Ws + I] = static_cast<float>(wx.coverage(I) * wy.coverage(J));
  }
  return out;
}

std::vector<float> render_plane_on_sensor(const std::vector<float>& plane, int W, int H, int Ws, int Hs,
                                          const std::vector<double>& fov, float outside) {
  std::vector<float> out(static_cast<size_t>(Ws) * Hs, outside);
  double sx = (fov[2] - fov[0]) / W, sy = (fov[3] - fov[1]) / H;
  for (int J = 0; J < Hs; ++J)
    for (int I = 0; I < Ws; ++I) {
      double i = std::floor((I + 0.5 - fov[0]) / sx), j = std::floor((J + 0.5 - fov[1]) / sy);
      if (i >= 0 && j >= 0 && i < W && j < H)
        out[static_cast<size_t>(J) * Ws + I] = plane[static_cast<size_t>(j) * W + static_cast<size_t>(i)];
    }
  return out;
}

// ---- PSF on the render grid -----------------------------------------------------------------

double blur_circle_um(const LensDescription& lens, const OpticsDescription& o, double d_mm) {
  double f = lens.focal_length_mm, A = f / lens.f_number;
  double v = image_distance_mm(lens, o);
  double vd = (d_mm > f && std::isfinite(d_mm)) ? f * d_mm / (d_mm - f) : (d_mm > 0 && d_mm <= f ? 1e30 : f);
  return A * std::fabs(v - vd) / vd * 1000.0;
}

namespace {

// Depth layers by blur-circle diameter in render pixels: 0 (in focus, below 1/8 pixel), then steps
// of 1/4 pixel up to 2.5 pixels (finer steps would not change what a pixel sees), then 10 % steps.
constexpr double kLinearStepPx = 0.25;
constexpr int kLinearLayers = 10;
constexpr double kLayerRatio = 1.1;
constexpr double kMaxBlurPx = 64;  // larger blur circles are capped (with a warning): kernels cost their area per pixel

int blur_layer(double c_px) {
  if (!(c_px >= 0.5 * kLinearStepPx)) return 0;
  c_px = std::min(c_px, kMaxBlurPx);
  double linear_end = kLinearStepPx * kLinearLayers;
  if (c_px < linear_end) return static_cast<int>(std::lround(c_px / kLinearStepPx));
  return kLinearLayers + static_cast<int>(std::lround(std::log(c_px / linear_end) / std::log(kLayerRatio)));
}
double layer_blur_px(int layer) {
  if (layer <= kLinearLayers) return layer * kLinearStepPx;
  return kLinearStepPx * kLinearLayers * std::pow(kLayerRatio, layer - kLinearLayers);
}

// The in-focus PSF of one band: Airy, measured (MTF table) or none.
RadialPsf band_psf(double nm, const LensDescription& lens, const OpticsDescription& o, double v_mm) {
  double nw = lens.f_number * v_mm / lens.focal_length_mm;  // working f-number
  if (!o.psf_images.empty()) return {};  // measured images are handled as kernels
  if (!o.mtf.empty()) {
    size_t k = o.mtf.nearest(nm);
    return psf_from_mtf(o.mtf.freq_cyc_per_mm[k], o.mtf.mtf[k], o.psf_extent_lambda_n * nm * 1e-3 * nw);
  }
  if (o.diffraction) return airy_psf(nm, nw, o.psf_extent_lambda_n);
  return {};
}

// Each source pixel q spreads its value with the kernel of its layer; sources beyond the frame
// repeat the edge pixel, so a uniform image stays uniform and no light leaves the frame.
void scatter_band(const std::vector<float>& in, int W, int H, const std::vector<int>& layer,
                  const std::vector<const PsfKernel*>& kernels, int margin, std::vector<float>* out) {
  out->assign(in.size(), 0.0f);
  for (int qy = -margin; qy < H + margin; ++qy)
    for (int qx = -margin; qx < W + margin; ++qx) {
      size_t src = static_cast<size_t>(std::clamp(qy, 0, H - 1)) * W + std::clamp(qx, 0, W - 1);
      float v = in[src];
      if (v == 0.0f) continue;
      const PsfKernel& k = *kernels[layer[src]];
      int r = k.radius;
      if (qx + r < 0 || qx - r >= W || qy + r < 0 || qy - r >= H) continue;
      for (int dy = std::max(-r, -qy); dy <= std::min(r, H - 1 - qy); ++dy) {
        float* o = out->data() + static_cast<size_t>(qy + dy) * W;
        const float* kw = k.w.data() + static_cast<size_t>(dy + r) * k.size() + r;
        for (int dx = std::max(-r, -qx); dx <= std::min(r, W - 1 - qx); ++dx) o[qx + dx] += v * kw[dx];
      }
    }
}

}  // namespace

SpectralImage blur_optical_image(const SpectralImage& img, const LensDescription& lens, const OpticsDescription& o,
                                 double pr, const std::vector<float>* depth_mm, nlohmann::json* info) {
  const int W = img.width, H = img.height, nb = img.bands();
  const size_t np = static_cast<size_t>(W) * H;
  std::vector<int> layer(np, 0);
  if (depth_mm)
    for (size_t i = 0; i < np; ++i) layer[i] = blur_layer(blur_circle_um(lens, o, (*depth_mm)[i]) / pr);
  std::vector<int> used;
  {
    std::vector<char> seen(blur_layer(kMaxBlurPx) + 1, 0);
    for (int l : layer) seen[l] = 1;
    for (size_t l = 0; l < seen.size(); ++l)
      if (seen[l]) used.push_back(static_cast<int>(l));
  }
  const double v_mm = image_distance_mm(lens, o);
  for (size_t i = 0; i < o.psf_images.size(); ++i) {  // a kernel costs its area per pixel and band
    const PsfImage& p = o.psf_images[i];
    double span_px = std::max(p.width, p.height) * p.pitch_um / pr;
    if (span_px > 257)
      throw InputError(i < o.psf_image_files.size() ? o.psf_image_files[i] : "psf_images", "pitch_um",
                       "the PSF image spans " + std::to_string(span_px) +
                           " render pixels (at most 257): crop it or render coarser");
  }
  SpectralImage out = img;
  std::vector<int> radius_first(used.size(), 0), radius_last(used.size(), 0);
  tbb::parallel_for(0, nb, [&](int b) {
    if (interrupt_requested()) return;  // Ctrl-C: the bands left are skipped, the image dropped below
    double nm = img.band_nm[b];
    RadialPsf base = band_psf(nm, lens, o, v_mm);
    PsfKernel measured;  // a measured PSF image on the render grid
    if (!o.psf_images.empty()) measured = image_kernel(o.psf_images[o.nearest_psf_image(nm)], pr, o.psf_supersample);
    double min_sample = 0.5 * nm * 1e-3 * lens.f_number;  // at least 2 samples per lambda N
    std::vector<PsfKernel> ks(used.size());
    std::vector<const PsfKernel*> by_layer(blur_layer(kMaxBlurPx) + 1, nullptr);
    int margin = 0;
    for (size_t u = 0; u < used.size(); ++u) {
      double c_um = layer_blur_px(used[u]) * pr;
      if (!o.psf_images.empty()) {  // measured image convolved with the pixel-integrated defocus disk
        ks[u] = c_um > 0 ? convolve_kernels(measured, pixel_kernel(defocus_psf({}, c_um), pr, o.psf_supersample, c_um / 16))
                         : measured;
        by_layer[used[u]] = &ks[u];
        margin = std::max(margin, ks[u].radius);
        if (b == 0) radius_first[u] = ks[u].radius;
        if (b == nb - 1) radius_last[u] = ks[u].radius;
        continue;
      }
      RadialPsf p = c_um > 0 ? defocus_psf(base, c_um) : base;
      if (p.empty()) {
        ks[u].radius = 0;
        ks[u].w = {1.0f};
        ks[u].raw_sum = 1;
      } else {
        ks[u] = pixel_kernel(p, pr, o.psf_supersample, min_sample);
      }
      by_layer[used[u]] = &ks[u];
      margin = std::max(margin, ks[u].radius);
      if (b == 0) radius_first[u] = ks[u].radius;
      if (b == nb - 1) radius_last[u] = ks[u].radius;
    }
    if (margin == 0) return;
    std::vector<float> plane(np);
    for (size_t i = 0; i < np; ++i) plane[i] = img.data[i * nb + b];
    std::vector<float> blurred;  // float sums: vectorised, relative error ~1e-6
    scatter_band(plane, W, H, layer, by_layer, margin, &blurred);
    for (size_t i = 0; i < np; ++i) out.data[i * nb + b] = static_cast<float>(blurred[i]);
  });
  throw_if_interrupted("blurring the image with the lens's PSF; nothing was written");
  if (info) {
    nlohmann::json layers = nlohmann::json::array();
    for (size_t u = 0; u < used.size(); ++u) {
      size_t count = std::count(layer.begin(), layer.end(), used[u]);
      layers.push_back({{"blur_diameter_um", layer_blur_px(used[u]) * pr},
                        {"render_pixels", count},
                        {"kernel_size_px_first_band", 2 * radius_first[u] + 1},
                        {"kernel_size_px_last_band", 2 * radius_last[u] + 1}});
    }
    (*info)["psf"] = !o.psf_images.empty() ? std::string("measured PSF images")
                     : o.mtf.empty()        ? std::string(o.diffraction ? "airy" : "none")
                                            : "measured MTF " + o.mtf.file;
    (*info)["working_f_number"] = lens.f_number * v_mm / lens.focal_length_mm;
    (*info)["depth_layers"] = layers;
  }
  return out;
}

// ---- the stage ------------------------------------------------------------------------------

namespace {

// Axial object distance (mm) of every render pixel from the EXR's aov.depth (ray length in m);
// 0 (nothing hit) means infinity (-1).
std::vector<float> axial_depth_mm(const SpectralImage& img, double vfov_deg) {
  const auto& t = img.aovs.at("aov.depth");
  double th = std::tan(0.5 * vfov_deg * kPi / 180.0), tw = th * img.width / img.height;
  std::vector<float> d(t.size(), -1.0f);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      size_t i = static_cast<size_t>(y) * img.width + x;
      double tx = (2.0 * (x + 0.5) / img.width - 1.0) * tw, ty = (1.0 - 2.0 * (y + 0.5) / img.height) * th;
      if (t[i] > 0 && std::isfinite(t[i])) d[i] = static_cast<float>(t[i] * 1000.0 / std::sqrt(1.0 + tx * tx + ty * ty));
    }
  return d;
}

// "columns 0-99 (left), rows 700-799 (bottom)": the sensor pixels outside [lo, hi) along each axis.
std::string outside_region(int n, double lo, double hi, const char* axis, const char* low_side, const char* high_side) {
  std::ostringstream s;
  int a = static_cast<int>(std::ceil(lo - 1e-9)), b = static_cast<int>(std::floor(hi + 1e-9));  // fully covered [a, b)
  a = std::clamp(a, 0, n);
  b = std::clamp(b, a, n);
  std::string sep;
  if (a > 0) {
    s << axis << " 0-" << a - 1 << " (" << low_side << ")";
    sep = ", ";
  }
  if (b < n) s << sep << axis << " " << b << "-" << n - 1 << " (" << high_side << ")";
  return s.str();
}

}  // namespace

OpticalImage form_optical_image(const SpectralImage& img, const CameraDescription& cam, const std::string& file) {
  const OpticsDescription& o = cam.optics;
  OpticalImage oi;
  if (!(cam.lens.focal_length_mm > 0))
    throw InputError(cam.source, "/lens/focal_length_mm", "the optics section needs the lens focal length");
  if (o.focus_distance_mm > 0 && !(o.focus_distance_mm > cam.lens.focal_length_mm))
    throw InputError(cam.source, "/optics/focus_distance_mm", "must be beyond the focal length (a real image)");
  std::optional<double> vfov = render_vfov_deg(img, &oi.warnings);
  if (!vfov)
    throw InputError(file, "oralfluor.vfov_deg",
                     "the optics stage needs the render's field of view (the EXR header attribute oralfluor.vfov_deg)");
  double v = image_distance_mm(cam.lens, o);
  RenderOnSensor m = map_render_to_sensor(img.width, img.height, *vfov, v, cam.sensor.pixel_pitch_um, o);

  // The blurred copy (render grid), the rows pass and the sensor image, all bands, as floats.
  const double nb = img.bands();
  check_memory(cam.source, "/optics/sensor_pixels",
               4.0 * nb * (double(img.width) * img.height + double(o.sensor_width_px) * (img.height + o.sensor_height_px)),
               "the optical image (" + std::to_string(o.sensor_width_px) + "x" + std::to_string(o.sensor_height_px) +
                   " sensor pixels, " + std::to_string(img.bands()) + " bands)");
  std::vector<float> depth;
  bool has_depth = img.aovs.count("aov.depth") > 0;
  if (o.defocus && has_depth) depth = axial_depth_mm(img, *vfov);
  if (o.defocus && !has_depth)
    oi.warnings.push_back("no aov.depth in " + file + ": defocus not simulated (everything in focus); render with AOVs");
  if (auto cm = img.attributes.find("oralfluor.camera_model"); cm != img.attributes.end() && cm->second == "thin_lens" &&
                                                              o.defocus && has_depth)
    oi.warnings.push_back("the image was rendered with a thin lens, which blurs out-of-focus depths already; the optics "
                          "stage adds its own defocus on top (render with a pinhole camera, or set optics.defocus false)");
  if (!depth.empty()) {
    size_t capped = 0;
    double largest = 0;
    for (float d : depth) {
      double c = blur_circle_um(cam.lens, o, d) / m.render_pitch_um;
      largest = std::max(largest, c);
      capped += c > kMaxBlurPx;
    }
    if (capped) {
      std::ostringstream w;
      w << capped << " render pixels have blur circles above " << kMaxBlurPx << " render pixels (up to " << largest
        << "); they are blurred with " << kMaxBlurPx << " (the focus is far from their depth)";
      oi.warnings.push_back(w.str());
    }
  }
  nlohmann::json psf_info;
  SpectralImage blurred = blur_optical_image(img, cam.lens, o, m.render_pitch_um, depth.empty() ? nullptr : &depth,
                                             &psf_info);
  std::vector<float> coverage;
  oi.image = resample_to_sensor(blurred, o.sensor_width_px, o.sensor_height_px, m, &coverage);
  oi.image.attributes.erase("oralfluor.vfov_deg");
  oi.axis_x_px = -o.offset_x_um / cam.sensor.pixel_pitch_um;
  oi.axis_y_px = -o.offset_y_um / cam.sensor.pixel_pitch_um;

  size_t none = 0, partial = 0;
  for (float c : coverage) {
    if (c <= 1e-6f) ++none;
    else if (c < 1.0f - 1e-4f) ++partial;
  }
  if (none + partial > 0) {
    std::ostringstream w;
    w << "the render's field of view does not cover the whole " << o.sensor_width_px << "x" << o.sensor_height_px
      << " sensor: " << none << " pixels without data and " << partial << " partly covered (zero light assumed there), in ";
    std::string cx = outside_region(o.sensor_width_px, m.x0, m.x0 + m.scale * img.width, "columns", "left", "right");
    std::string ry = outside_region(o.sensor_height_px, m.y0, m.y0 + m.scale * img.height, "rows", "top", "bottom");
    w << cx << (cx.empty() || ry.empty() ? "" : ", ") << ry;
    oi.warnings.push_back(w.str());
  }
  if (m.scale > 1.0 + 1e-9) {
    std::ostringstream w;
    w << "a render pixel covers " << m.scale << " sensor pixels: the sensor image is no sharper than the render "
      << "(render at least " << static_cast<int>(std::ceil(img.width * m.scale)) << "x"
      << static_cast<int>(std::ceil(img.height * m.scale)) << " to resolve the sensor)";
    oi.warnings.push_back(w.str());
  }
  oi.info = psf_info;
  oi.info["sensor_pixels"] = {o.sensor_width_px, o.sensor_height_px};
  oi.info["sensor_offset_um"] = {o.offset_x_um, o.offset_y_um};
  oi.info["image_distance_mm"] = v;
  oi.info["render_pixel_on_sensor_um"] = m.render_pitch_um;
  oi.info["render_pixels_per_sensor_pixel"] = 1.0 / m.scale;
  oi.info["render_fov_on_sensor_px"] = {m.x0, m.y0, m.x0 + m.scale * img.width, m.y0 + m.scale * img.height};
  oi.info["pixels_without_data"] = none;
  oi.info["pixels_partly_covered"] = partial;
  oi.info["defocus"] = o.defocus && has_depth;
  return oi;
}

}  // namespace ofl
