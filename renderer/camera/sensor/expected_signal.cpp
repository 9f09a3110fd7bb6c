#include "renderer/camera/sensor/expected_signal.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "renderer/core/errors/error.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {
namespace {

constexpr int kRadiusSamples = 257;
constexpr double kMaxStepNm = 0.25;

// Sample wavelengths for integrating over [lo, hi]: uniform steps of at most kMaxStepNm plus every
// kink of the factors inside the interval, each kink also 1e-7 nm to either side so that a jump
// (a table that is zero outside its range) is integrated as a step, not as a ramp over one step.
std::vector<double> sample_points(double lo, double hi, const std::vector<const std::vector<double>*>& kink_lists) {
  int n = std::max(8, static_cast<int>(std::ceil((hi - lo) / kMaxStepNm)));
  std::vector<double> xs;
  xs.reserve(n + 1);
  for (int i = 0; i <= n; ++i) xs.push_back(lo + (hi - lo) * i / n);
  for (auto* kinks : kink_lists)
    for (double k : *kinks)
      for (double x : {k - 1e-7, k, k + 1e-7})
        if (x > lo && x < hi) xs.push_back(x);
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  return xs;
}

}  // namespace

double system_qe(const CameraDescription& cam, int c, double nm, double aoi_front, double aoi_sensor) {
  return cam.lens.transmittance(nm) * cam.filters.transmittance(nm, aoi_front, aoi_sensor) * cam.sensor.qe[c](nm);
}

ResponseTable build_response_table(const CameraDescription& cam, const FieldGeometry& g,
                                   const std::vector<double>& band_lo, const std::vector<double>& band_hi) {
  ResponseTable t;
  t.bands = static_cast<int>(band_lo.size());
  bool varies = cam.filters.any_interference() && (g.pixels_per_tan > 0 || g.sensor_tan_per_px > 0);
  int n = varies ? kRadiusSamples : 1;
  double rmax = g.max_radius_px();
  for (int k = 0; k < n; ++k) t.radius_px.push_back(n == 1 ? 0.0 : rmax * k / (n - 1));
  t.w.assign(static_cast<size_t>(n) * 3 * t.bands, 0.0);
  const SensorDescription& s = cam.sensor;
  // Everything but the spectral integral and cos^4: t * A * fill * pi / (1 + 4 N^2 (1 - m)^2) / (h c) * 1e-9 (nm -> m).
  double scale = s.exposure_s * s.pixel_area_m2() * s.fill_factor * irradiance_factor(cam.lens) * 1e-9 /
                 (kPlanck * kSpeedOfLight);
  tbb::parallel_for(0, n, [&](int k) {
    double r = t.radius_px[k];
    double af = g.field_angle(r), as = g.sensor_angle(r);
    Spectrum stack = cam.filters.at_angles(af, as);
    std::vector<const std::vector<double>*> kinks = {&cam.lens.transmittance.kinks, &stack.kinks};
    for (int c = 0; c < 3; ++c) kinks.push_back(&s.qe[c].kinks);
    for (int b = 0; b < t.bands; ++b) {
      std::vector<double> xs = sample_points(band_lo[b], band_hi[b], kinks);
      std::vector<double> common(xs.size());
      for (size_t i = 0; i < xs.size(); ++i) common[i] = cam.lens.transmittance(xs[i]) * stack(xs[i]) * xs[i];
      for (int c = 0; c < 3; ++c) {
        double sum = 0, prev = common[0] * s.qe[c](xs[0]);
        for (size_t i = 1; i < xs.size(); ++i) {
          double cur = common[i] * s.qe[c](xs[i]);
          sum += 0.5 * (prev + cur) * (xs[i] - xs[i - 1]);
          prev = cur;
        }
        t.w[(static_cast<size_t>(k) * 3 + c) * t.bands + b] = scale * sum;
      }
    }
  });
  return t;
}

ExpectedSignal expected_electrons(const SpectralImage& img, const CameraDescription& cam, const FieldGeometry& g) {
  ResponseTable table = build_response_table(cam, g, img.band_lo(), img.band_hi());
  ExpectedSignal out;
  out.width = img.width;
  out.height = img.height;
  out.channel_e.assign(static_cast<size_t>(img.width) * img.height * 3, 0.0f);
  out.mosaic_e.assign(static_cast<size_t>(img.width) * img.height, 0.0f);
  out.dark_e = cam.sensor.dark_electrons();
  const int nb = img.bands();
  const int nk = static_cast<int>(table.radius_px.size());
  const double rmax = g.max_radius_px();
  tbb::parallel_for(tbb::blocked_range<int>(0, img.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y)
      for (int x = 0; x < img.width; ++x) {
        double r = g.radius_px(x, y);
        int k0 = 0;
        double f = 0;
        if (nk > 1 && rmax > 0) {
          double u = std::clamp(r / rmax, 0.0, 1.0) * (nk - 1);
          k0 = std::min(static_cast<int>(u), nk - 2);
          f = u - k0;
        }
        double vign = relative_illumination(cam.lens, g.field_angle(r));
        const float* L = img.pixel(x, y);
        size_t p = static_cast<size_t>(y) * img.width + x;
        for (int c = 0; c < 3; ++c) {
          const double* w0 = table.weights(k0, c);
          const double* w1 = nk > 1 ? table.weights(k0 + 1, c) : w0;
          double e = 0;
          for (int b = 0; b < nb; ++b) e += L[b] * ((1.0 - f) * w0[b] + f * w1[b]);
          out.channel_e[p * 3 + c] = static_cast<float>(e * vign);
        }
        out.mosaic_e[p] = out.channel_e[p * 3 + cfa_channel(cam.sensor.cfa, x, y)];
      }
  });
  return out;
}

void check_radiance(SpectralImage& img, const std::string& file, std::vector<std::string>* warnings) {
  size_t negative = 0;
  double most_negative = 0;
  const int nb = img.bands();
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      float* p = img.pixel(x, y);
      for (int b = 0; b < nb; ++b) {
        if (!std::isfinite(p[b])) {
          std::ostringstream f;
          f << "pixel (" << x << ", " << y << ") band " << img.band_nm[b] << " nm";
          throw InputError(file, f.str(), "radiance is NaN or infinite");
        }
        if (p[b] < 0) {
          ++negative;
          most_negative = std::min<double>(most_negative, p[b]);
          p[b] = 0;
        }
      }
    }
  if (negative && warnings) {
    std::ostringstream w;
    w << negative << " negative radiance values (down to " << most_negative << ") clipped to zero";
    warnings->push_back(w.str());
  }
}

double response_outside_bands(const CameraDescription& cam, const std::vector<double>& lo,
                              const std::vector<double>& hi) {
  double a = 1e300, b = 0;
  for (int c = 0; c < 3; ++c)
    if (cam.sensor.qe[c].kinks.size() >= 2) {
      a = std::min(a, cam.sensor.qe[c].kinks.front());
      b = std::max(b, cam.sensor.qe[c].kinks.back());
    }
  if (!(b > a) || lo.empty()) return 0.0;
  double total = 0, inside = 0;
  for (double nm = a; nm <= b; nm += 0.5) {
    double v = 0;
    for (int c = 0; c < 3; ++c) v += system_qe(cam, c, nm, 0, 0) * nm;
    total += v;
    bool in = false;
    for (size_t i = 0; i < lo.size() && !in; ++i) in = nm >= lo[i] && nm <= hi[i];
    if (in) inside += v;
  }
  return total > 0 ? 1.0 - inside / total : 0.0;
}

}  // namespace ofl
