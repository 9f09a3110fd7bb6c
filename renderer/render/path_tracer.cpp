#include "renderer/render/path_tracer.h"

#include "renderer/render/albedo_matrix.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace ofl {

PathTracer::PathTracer(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables)
    : scene_(scene), embree_(embree), t_(tables) {
  const CameraSpec& c = scene.camera;
  cam_pos_ = c.position;
  cam_fwd_ = glm::normalize(c.look_at - c.position);
  cam_right_ = glm::normalize(glm::cross(cam_fwd_, c.up));
  cam_up_ = glm::cross(cam_right_, cam_fwd_);
  tan_half_h_ = std::tan(0.5 * c.vfov_deg * kPi / 180.0);
  tan_half_w_ = tan_half_h_ * double(c.width) / c.height;
}

PathTracer::Ray PathTracer::camera_ray(int x, int y, Rng& rng) const {
  const CameraSpec& c = scene_.camera;
  double sx = (2.0 * (x + rng.next_double()) / c.width - 1.0) * tan_half_w_;
  double sy = (1.0 - 2.0 * (y + rng.next_double()) / c.height) * tan_half_h_;
  glm::dvec3 d = glm::normalize(cam_fwd_ + sx * cam_right_ + sy * cam_up_);
  if (c.model == CameraSpec::Model::kPinhole) return {cam_pos_, d};
  // Thin lens: every ray through the pixel's point on the focus plane.
  double ft = c.focus_distance_m / glm::dot(d, cam_fwd_);
  glm::dvec3 focus = cam_pos_ + ft * d;
  glm::dvec2 lens = sample_concentric_disk(rng.next_double(), rng.next_double()) * c.aperture_radius_m();
  glm::dvec3 o = cam_pos_ + lens.x * cam_right_ + lens.y * cam_up_;
  return {o, glm::normalize(focus - o)};
}

namespace {

inline double power_heuristic(double a, double b) { return a * a / (a * a + b * b); }

}  // namespace

double PathTracer::sample_pixel(int x, int y, Rng& rng, double* bands, RayCounts& counts, RayLog* log,
                                double* fluorescence) const {
  const int n = t_.n;
  const bool deterministic = scene_.integrator.direct_excitation == IntegratorSpec::DirectExcitation::kDeterministic;
  auto record = [&](const glm::dvec3& o, const glm::dvec3& d, float tmax, bool shadow) {
    if (log && log->rays.size() < log->limit)
      log->rays.push_back({{float(o.x), float(o.y), float(o.z)}, {float(d.x), float(d.y), float(d.z)}, tmax, shadow});
  };

  // Camera wavelengths: stratified over the CDF, one uniform offset shared by the lanes.
  int film[kLanes], wl[kLanes];
  float beta[kLanes], L[kLanes], Lf[kLanes];
  bool fl[kLanes];  // the lane's light has been re-radiated (it is fluorescence)
  // The lane was re-radiated at the previous vertex. With deterministic direct excitation, next-event
  // estimation there already counted all LED light exciting that vertex (weight 1), so a BSDF-sampled
  // hit of an LED right after a re-radiation counts 0: a one-or-nothing partition instead of MIS,
  // because the directional MIS weights ignore how poorly the sampled excitation wavelength
  // matches a narrow LED line.
  bool rerad_prev[kLanes];
  double u0 = rng.next_double();
  for (int k = 0; k < kLanes; ++k) {
    double u = u0 + double(k) / kLanes;
    if (u >= 1) u -= 1;
    film[k] = wl[k] = t_.wavelength_pdf.sample(u);
    beta[k] = 1;
    L[k] = Lf[k] = 0;
    fl[k] = false;
    rerad_prev[k] = false;
  }

  Ray ray = camera_ray(x, y, rng);
  counts.camera++;
  double prev_pdf = 0;  // solid-angle pdf of the direction that produced `ray`, 0 = camera/delta
  bool diffuse_seen = false;  // the path has left a surface through its diffuse lobe
  const int max_depth = scene_.integrator.max_depth;
  for (int depth = 0;; ++depth) {
    record(ray.o, ray.d, 1e30f, false);
    RayHit hit = embree_.intersect(ray.o, ray.d);
    if (!hit.found()) break;
    const GeomInfo& gi = embree_.info(hit.geom);

    if (gi.kind == GeomInfo::Kind::kLed) {
      const LedLight& led = scene_.lights[gi.index];
      double cos_l = -glm::dot(ray.d, led.axis);
      if (cos_l > 0) {
        double prof = led.profile.eval(cos_l) / (led.area() * cos_l) * t_.light_scale[gi.index];
        double w = 1.0;
        if (prev_pdf > 0) {
          double pl = t_.light_select.pdf(gi.index) * double(hit.t) * hit.t / (led.area() * cos_l);
          w = power_heuristic(prev_pdf, pl);
        }
        const float* shape = t_.light_shape[t_.light_group[gi.index]].data();
        for (int k = 0; k < kLanes; ++k) {
          if (deterministic && rerad_prev[k]) continue;
          float c = float(beta[k] * shape[wl[k]] * prof * w);
          L[k] += c;
          if (fl[k]) Lf[k] += c;
        }
      }
      break;  // the LED body absorbs
    }

    SurfacePoint sp = embree_.surface(hit, ray.o, ray.d);
    glm::dvec3 wo_w = -ray.d;
    // Two-sided surfaces: work on the side the ray came from.
    if (glm::dot(sp.ng, wo_w) < 0) { sp.ng = -sp.ng; sp.ns = -sp.ns; }
    if (glm::dot(sp.ns, wo_w) <= 1e-6) sp.ns = sp.ng;
    const MaterialTables& mt = t_.materials[sp.material];
    if (!mt.emission.empty())
      for (int k = 0; k < kLanes; ++k) {
        L[k] += beta[k] * mt.emission[wl[k]];
        if (fl[k]) Lf[k] += beta[k] * mt.emission[wl[k]];
      }
    if (depth >= max_depth) break;

    LocalMaterial lm{&mt};
    if (mt.reflectance_texture >= 0) lm.rscale = scene_.textures[mt.reflectance_texture].lookup(sp.uv.x, sp.uv.y);
    lm.nf = std::min<int>(int(mt.fluorophores.size()), kMaxFluorophoresPerMaterial);  // more is refused at load
    for (int j = 0; j < lm.nf; ++j) {
      const auto& f = mt.fluorophores[j];
      float factor = 1.0f;
      if (f.texture >= 0) factor = std::max(0.0f, f.texture_offset + f.texture_scale * scene_.textures[f.texture].lookup(sp.uv.x, sp.uv.y));
      lm.conc[j] = f.concentration * factor;
    }

    const GgxCoating& coat = diffuse_seen ? mt.coating_regularized : mt.coating;
    Frame frame(sp.ns);
    glm::dvec3 wo = frame.to_local(wo_w);
    // The base is reached after n internal reflections inside the coating (shared by the lanes);
    // each lane walks n albedo-matrix steps first (DESIGN: coated.h).
    int wl_base[kLanes];
    float w_base[kLanes];
    bool fl_base[kLanes];
    for (int k = 0; k < kLanes; ++k) { wl_base[k] = wl[k]; w_base[k] = 1; fl_base[k] = fl[k]; }
    if (mt.coated) {
      int bounces = 0;
      while (bounces < 64 && rng.next_double() < coat.internal_reflectance) ++bounces;
      for (int b = 0; b < bounces; ++b)
        for (int k = 0; k < kLanes; ++k)
          if (beta[k] > 0) w_base[k] *= albedo_step(lm, wl_base[k], rng, n, &fl_base[k]);
    }
    const double p_spec = mt.coated ? std::clamp(coat.specular_albedo(wo.z), 0.1, 0.9) : 0.0;
    auto kernel = [&](const glm::dvec3& wi) {
      return mt.coated ? coat.diffuse_kernel(wi.z, wo.z) : 1.0 / kPi;
    };
    auto dir_pdf = [&](const glm::dvec3& wi) {
      double pd = cosine_hemisphere_pdf(wi.z);
      return mt.coated ? p_spec * coat.pdf(wo, wi) + (1 - p_spec) * pd : pd;
    };

    // Next-event estimation to one LED chosen by power.
    if (!scene_.lights.empty()) {
      int li = t_.light_select.sample(rng.next_double());
      const LedLight& led = scene_.lights[li];
      glm::dvec3 lp = led.position;
      if (!led.is_point()) {
        glm::dvec2 d = sample_concentric_disk(rng.next_double(), rng.next_double()) * led.radius_m;
        lp += d.x * led.tangent + d.y * led.bitangent;
      }
      glm::dvec3 to = lp - sp.p;
      double dist2 = glm::dot(to, to);
      double dist = std::sqrt(dist2);
      glm::dvec3 wi_w = to / dist;
      double cos_l = -glm::dot(wi_w, led.axis);
      glm::dvec3 wi = frame.to_local(wi_w);
      if (cos_l > 0 && wi.z > 0 && glm::dot(wi_w, sp.ng) > 0) {
        glm::dvec3 o = EmbreeScene::offset(sp, wi_w);
        float tmax = float(glm::length(lp - o) * (1.0 - 1e-4));
        counts.shadow++;
        record(o, wi_w, tmax, true);
        if (!embree_.occluded(o, wi_w, tmax)) {
          double pl = t_.light_select.pdf(li);
          double g = led.profile.eval(cos_l) * wi.z / dist2 / pl * t_.light_scale[li];
          double w = 1.0;
          if (!led.is_point()) w = power_heuristic(pl * dist2 / (led.area() * cos_l), dir_pdf(wi));
          double fs = mt.coated ? coat.eval(wo, wi) : 0.0;
          double kd = kernel(wi);
          int grp = t_.light_group[li];
          const float* shape = t_.light_shape[grp].data();
          for (int k = 0; k < kLanes; ++k) {
            if (beta[k] == 0) continue;
            int b = wl_base[k];
            double reflected = 0, fluoresced = 0;
            if (deterministic || lm.nf == 0) {
              reflected = mt.reflectance[b] * lm.rscale * shape[b];
              for (int j = 0; j < lm.nf; ++j) fluoresced += lm.conc[j] * mt.fluorophores[j].direct[grp][b];
            } else {
              int s = b;
              bool rr = false;
              float tot = albedo_step(lm, s, rng, n, &rr);
              (rr ? fluoresced : reflected) = tot * shape[s];
            }
            double spec = beta[k] * fs * shape[wl[k]] * g * w;
            double dif_r = beta[k] * kd * w_base[k] * reflected * g * w;
            double dif_f = beta[k] * kd * w_base[k] * fluoresced * g * (deterministic ? 1.0 : w);
            L[k] += float(spec + dif_r + dif_f);
            Lf[k] += float((fl[k] ? spec : 0.0) + (fl_base[k] ? dif_r : 0.0) + dif_f);
          }
        }
      }
    }

    // Continue the path: one direction for all lanes, then each lane picks its event.
    glm::dvec3 wi;
    if (mt.coated && rng.next_double() < p_spec) {
      wi = coat.sample(wo, rng.next_double(), rng.next_double());
    } else {
      wi = sample_cosine_hemisphere(rng.next_double(), rng.next_double());
      diffuse_seen = scene_.integrator.regularize_glossy > 0;
    }
    if (wi.z <= 0) break;
    glm::dvec3 wi_w = frame.to_world(wi);
    if (glm::dot(wi_w, sp.ng) <= 0) break;
    double pdf = dir_pdf(wi);
    if (!(pdf > 0)) break;
    double fs = mt.coated ? coat.eval(wo, wi) : 0.0;
    double kd = kernel(wi);
    double geo = wi.z / pdf;
    float maxb = 0;
    for (int k = 0; k < kLanes; ++k) {
      if (beta[k] == 0) continue;
      int b = wl_base[k];
      double a = fs;
      double r = kd * w_base[k] * mt.reflectance[b] * lm.rscale;
      const float f_em = lm.nf ? fluor_total(lm, b) : 0.0f;
      double f = kd * w_base[k] * f_em;
      double tot = a + r + f;
      if (!(tot > 0)) { beta[k] = 0; continue; }
      double u = rng.next_double() * tot;
      rerad_prev[k] = false;
      if (u >= a) {
        wl[k] = b;
        fl[k] = fl_base[k];
        if (u >= a + r) {
          wl[k] = sample_excitation(lm, b, f_em, rng.next_float(), n);
          fl[k] = true;
          rerad_prev[k] = true;
        }
      }
      beta[k] = float(beta[k] * tot * geo);
      maxb = std::max(maxb, beta[k]);
    }
    if (maxb <= 0) break;
    prev_pdf = pdf;
    if (depth + 1 >= scene_.integrator.rr_start_depth) {
      float q = std::min(1.0f, maxb);
      if (q < 1.0f) {
        if (rng.next_float() >= q) break;
        for (int k = 0; k < kLanes; ++k) beta[k] /= q;
      }
    }
    ray = {EmbreeScene::offset(sp, wi_w), wi_w};
    counts.extension++;
  }

  double total = 0;
  for (int k = 0; k < kLanes; ++k) {
    if (L[k] == 0) continue;
    double v = double(L[k]) * t_.film_scale[film[k]] / kLanes;
    double vf = double(Lf[k]) * t_.film_scale[film[k]] / kLanes;
    for (const auto& bw : t_.band_weights[film[k]]) {
      bands[bw.band] += bw.weight * v;
      total += bw.weight * v;
      if (fluorescence) fluorescence[bw.band] += bw.weight * vf;
    }
  }
  return total;
}

}  // namespace ofl
