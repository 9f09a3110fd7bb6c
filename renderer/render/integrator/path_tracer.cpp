#include "renderer/render/integrator/path_tracer.h"

#include "renderer/render/integrator/layered_bsdf.h"
#include "renderer/render/integrator/led_connection.h"
#include "renderer/render/material/albedo_matrix.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

#include <glm/geometric.hpp>

namespace ofl {
namespace {

constexpr double kMmPerMetre = 1000.0;

// The material under a point of a volume walk (transport "volume", layered_bsdf.h): the point of
// the vertex's tangent plane at the walk's lateral offset, its texture coordinates extrapolated
// along the plane from the hit triangle's, resolved as the surface resolves its `regions`. The
// surface is taken as flat over the walk's spread.
class TangentPlaneRegions final : public LateralMaterials {
 public:
  TangentPlaneRegions(const Scene& sc, int base, const SurfacePoint& sp, const Frame& f, const UvGradient& g)
      : sc_(sc), base_(base), p_(sp.p), uv_(sp.uv), x_(f.x / kMmPerMetre), y_(f.y / kMmPerMetre), g_(g),
        metric_{glm::dot(g.u, g.u), glm::dot(g.u, g.v), glm::dot(g.v, g.v)} {}
  int material_at(const glm::dvec2& pos) const override {
    const glm::dvec3 d = offset(pos);
    const glm::vec2 uv = uv_at(d);
    return resolve_material(sc_, base_, uv.x, uv.y, p_ + d);
  }
  double clearance(const glm::dvec2& pos) const override {
    const glm::dvec3 d = offset(pos);
    const glm::vec2 uv = uv_at(d);
    return region_clearance_m(sc_, base_, p_ + d, uv.x, uv.y, metric_) * kMmPerMetre;
  }

 private:
  // The plane's point at lateral position pos (mm) as an offset from the vertex (m), and its
  // texture coordinates extrapolated along the plane.
  glm::dvec3 offset(const glm::dvec2& pos) const { return pos.x * x_ + pos.y * y_; }
  glm::vec2 uv_at(const glm::dvec3& d) const { return uv_ + glm::vec2(float(glm::dot(g_.u, d)), float(glm::dot(g_.v, d))); }

  const Scene& sc_;
  int base_;
  glm::dvec3 p_;
  glm::vec2 uv_;
  glm::dvec3 x_, y_;  // the frame's tangent axes per mm
  UvGradient g_;
  UvMetric metric_;  // the texture coordinates' stretch along the plane (region_clearance_m)
};

// A surface material at a point: its reflectance texture's scale and its fluorophores'
// concentrations there.
LocalMaterial local_material(const MaterialTables& mt, const std::vector<Texture>& textures, const glm::vec2& uv) {
  LocalMaterial lm{&mt};
  if (mt.reflectance_texture >= 0) lm.rscale = textures[mt.reflectance_texture].lookup(uv.x, uv.y);
  lm.nf = std::min<int>(int(mt.fluorophores.size()), kMaxFluorophoresPerMaterial);  // more is refused at load
  for (int j = 0; j < lm.nf; ++j) {
    const auto& f = mt.fluorophores[j];
    float factor = 1.0f;
    if (f.texture >= 0) factor = std::max(0.0f, f.texture_offset + f.texture_scale * textures[f.texture].lookup(uv.x, uv.y));
    lm.conc[j] = f.concentration * factor;
  }
  return lm;
}

// Each lane's state where it reaches a coated surface's base: the wavelength, fluorescence flag and
// weight after the internal reflections inside the coating, a number shared by the lanes (each lane
// walks that many albedo-matrix steps, materials/interfaces/coated.h). Uncoated: the lane as it came.
struct BaseLanes {
  int wl[kLanes];
  float w[kLanes];
  bool fl[kLanes];
};
BaseLanes reach_base(const MaterialTables& mt, const GgxCoating& coat, const LocalMaterial& lm, const PathLanes& p, Rng& rng,
                     int n) {
  BaseLanes b;
  for (int k = 0; k < kLanes; ++k) { b.wl[k] = p.wl[k]; b.w[k] = 1; b.fl[k] = p.fl[k]; }
  if (!mt.coated) return b;
  int bounces = 0;
  while (bounces < 64 && rng.next_double() < coat.internal_reflectance) ++bounces;
  for (int i = 0; i < bounces; ++i)
    for (int k = 0; k < kLanes; ++k)
      if (p.beta[k] > 0) b.w[k] *= albedo_step(lm, b.wl[k], rng, n, &b.fl[k]);
  return b;
}

}  // namespace

const char* stage_name(int stage) {
  static const char* names[kStages] = {"camera rays", "intersection", "hit point and material", "light choice",
                                       "shadow rays",  "surface shading", "layered tissue",       "film"};
  return stage >= 0 && stage < kStages ? names[stage] : "?";
}

uint64_t stage_clock() {
#if defined(__x86_64__) || defined(__i386__)
  return __rdtsc();
#else
  return uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count());
#endif
}

void record_ray(RayLog* log, const glm::dvec3& o, const glm::dvec3& d, float tmax, bool shadow) {
  if (log && log->rays.size() < log->limit)
    log->rays.push_back({{float(o.x), float(o.y), float(o.z)}, {float(d.x), float(d.y), float(d.z)}, tmax, shadow});
}

PathTracer::PathTracer(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables)
    : scene_(scene),
      embree_(embree),
      t_(tables),
      // 16 guide cells per wavelength bin (about 1 500 ints for 360-830 nm at 5 nm, small enough to
      // stay in the first-level cache): all but about one cell in 16 name their bin outright, so the
      // eight draws of a camera sample rarely walk the CDF (the same bins as any guide, so the same
      // images).
      wavelengths_(tables.wavelength_pdf, 16),
      light_choice_(scene.lights, tables.light_select,
                    scene.integrator.light_selection == IntegratorSpec::LightSelection::kPower),
      spatial_(scene, embree, tables) {
  for (const auto& w : tables.band_weights) {
    film_first_.push_back(int(film_bw_.size()));
    film_bw_.insert(film_bw_.end(), w.begin(), w.end());
  }
  film_first_.push_back(int(film_bw_.size()));
  deterministic_ = scene.integrator.direct_excitation == IntegratorSpec::DirectExcitation::kDeterministic;
  for (const LedLight& l : scene.lights) hittable_emitters_ = hittable_emitters_ || !l.is_point();
  for (const MaterialTables& m : tables.materials) hittable_emitters_ = hittable_emitters_ || !m.emission.empty();
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

// Camera wavelengths: stratified over the CDF, one uniform offset shared by the lanes.
void PathTracer::init_lanes(PathLanes& p, Rng& rng) const {
  double u0 = rng.next_double();
  for (int k = 0; k < kLanes; ++k) {
    double u = u0 + double(k) / kLanes;
    if (u >= 1) u -= 1;
    p.film[k] = p.wl[k] = wavelengths_.sample(u);
    p.beta[k] = 1;
    p.L[k] = p.Lf[k] = 0;
    p.fl[k] = false;
    p.rerad_prev[k] = false;
  }
}

void PathTracer::hit_led(const RayHit& hit, const Ray& ray, double prev_pdf, const SurfacePoint& prev, bool prev_by_power,
                         PathLanes& p) const {
  const GeomInfo& gi = embree_.info(hit.geom);
  const LedLight& led = scene_.lights[gi.index];
  double cos_l = -glm::dot(ray.d, led.axis);
  if (cos_l <= 0) return;
  double prof = led.profile.eval(cos_l) / (led.area() * cos_l) * t_.light_scale[gi.index];
  double w = 1.0;
  if (prev_pdf > 0) {
    const double pick = prev_by_power ? t_.light_select.pdf(gi.index) : light_choice_.pmf(gi.index, prev.p, prev.ns, prev.ng);
    double pl = pick * double(hit.t) * hit.t / (led.area() * cos_l);
    w = power_heuristic(prev_pdf, pl);
  }
  const float* shape = t_.light_shape[t_.light_group[gi.index]].data();
  for (int k = 0; k < kLanes; ++k) {
    if (p.rerad_prev[k]) continue;
    p.add(k, p.beta[k] * shape[p.wl[k]] * prof * w);
  }
}

// Next-event estimation to one LED chosen by what it can give this point (light_choice.h): a point
// on it, the shadow ray, the geometry.
LightSample PathTracer::sample_light(const SurfacePoint& sp, const Frame& frame, Rng& rng, RayCounts& counts,
                                     RayLog* log) const {
  LightSample s;
  if (scene_.lights.empty()) return s;
  const LightPick pick = light_choice_.pick(sp.p, sp.ns, sp.ng, rng.next_double());
  if (pick.light < 0) {
    counts.mark(Stage::kLightChoice);
    return s;
  }
  return connect_to_led(scene_, embree_, t_, pick.light, pick.pmf, sp, frame, rng, counts, log);
}

PathTracer::Continuation PathTracer::surface_vertex(const SurfacePoint& sp, const Frame& frame, const glm::dvec3& wo,
                                                    const MaterialTables& mt, bool diffuse_seen, PathLanes& p, Rng& rng,
                                                    RayCounts& counts, RayLog* log) const {
  const int n = t_.n;
  const LocalMaterial lm = local_material(mt, scene_.textures, sp.uv);

  const GgxCoating& coat = diffuse_seen ? mt.coating_regularized : mt.coating;
  const BaseLanes base = reach_base(mt, coat, lm, p, rng, n);
  const int* wl_base = base.wl;
  const float* w_base = base.w;
  const bool* fl_base = base.fl;
  const double p_spec = mt.coated ? std::clamp(coat.specular_albedo(wo.z), 0.1, 0.9) : 0.0;
  auto kernel = [&](const glm::dvec3& wi) { return mt.coated ? coat.diffuse_kernel(wi.z, wo.z) : 1.0 / kPi; };
  auto dir_pdf = [&](const glm::dvec3& wi) {
    double pd = cosine_hemisphere_pdf(wi.z);
    return mt.coated ? p_spec * coat.pdf(wo, wi) + (1 - p_spec) * pd : pd;
  };

  counts.mark(Stage::kShading);
  LightSample ls = sample_light(sp, frame, rng, counts, log);
  if (ls.valid) {
    const glm::dvec3& wi = ls.wi;
    double w = ls.pdf_solid > 0 ? power_heuristic(ls.pdf_solid, dir_pdf(wi)) : 1.0;
    double fs = mt.coated ? coat.eval(wo, wi) : 0.0;
    double kd = kernel(wi);
    const float* shape = t_.light_shape[ls.group].data();
    for (int k = 0; k < kLanes; ++k) {
      if (p.beta[k] == 0) continue;
      int b = wl_base[k];
      double reflected = 0, fluoresced = 0;
      if (deterministic_ || lm.nf == 0) {
        reflected = mt.reflectance[b] * lm.rscale * shape[b];
        for (int j = 0; j < lm.nf; ++j) fluoresced += lm.conc[j] * mt.fluorophores[j].direct[ls.group][b];
      } else {
        int s = b;
        bool rr = false;
        float tot = albedo_step(lm, s, rng, n, &rr);
        (rr ? fluoresced : reflected) = tot * shape[s];
      }
      double spec = p.beta[k] * fs * shape[p.wl[k]] * ls.g * w;
      double dif_r = p.beta[k] * kd * w_base[k] * reflected * ls.g * w;
      double dif_f = p.beta[k] * kd * w_base[k] * fluoresced * ls.g * (deterministic_ ? 1.0 : w);
      p.L[k] += float(spec + dif_r + dif_f);
      p.Lf[k] += float((p.fl[k] ? spec : 0.0) + (fl_base[k] ? dif_r : 0.0) + dif_f);
    }
  }

  // Continue the path: one direction for all lanes, then each lane picks its event.
  Continuation c;
  if (embree_.outward_face(sp)) return c;  // whatever direction it samples leaves the scene
  glm::dvec3 wi;
  if (mt.coated && rng.next_double() < p_spec) {
    wi = coat.sample(wo, rng.next_double(), rng.next_double());
  } else {
    wi = sample_cosine_hemisphere(rng.next_double(), rng.next_double());
    c.diffuse = true;
  }
  if (wi.z <= 0) return c;
  glm::dvec3 wi_w = frame.to_world(wi);
  if (glm::dot(wi_w, sp.ng) <= 0) return c;
  // A continuation ray that can hit nothing ends the path here: its lanes' events would not matter.
  if (embree_.leaves_scene(EmbreeScene::offset(sp, wi_w), wi_w)) return c;
  double pdf = dir_pdf(wi);
  if (!(pdf > 0)) return c;
  double fs = mt.coated ? coat.eval(wo, wi) : 0.0;
  double kd = kernel(wi);
  double geo = wi.z / pdf;
  for (int k = 0; k < kLanes; ++k) {
    if (p.beta[k] == 0) continue;
    int b = wl_base[k];
    double a = fs;
    double r = kd * w_base[k] * mt.reflectance[b] * lm.rscale;
    const float f_em = lm.nf ? fluor_total(lm, b) : 0.0f;
    double f = kd * w_base[k] * f_em;
    double tot = a + r + f;
    if (!(tot > 0)) { p.beta[k] = 0; continue; }
    double u = rng.next_double() * tot;
    p.rerad_prev[k] = false;
    if (u >= a) {
      p.wl[k] = b;
      p.fl[k] = fl_base[k];
      if (u >= a + r) {
        p.wl[k] = sample_excitation(lm, b, f_em, rng.next_float(), n);
        p.fl[k] = true;
        p.rerad_prev[k] = deterministic_;
      }
    }
    p.beta[k] = float(p.beta[k] * tot * geo);
  }
  c.ok = true;
  c.wi_world = wi_w;
  c.pdf = pdf;
  return c;
}

PathTracer::Continuation PathTracer::layered_vertex(const SurfacePoint& sp, const RayHit& hit, const Frame& frame,
                                                    const glm::dvec3& wo, const MaterialTables& mt, PathLanes& p,
                                                    Rng& rng, RayCounts& counts, RayLog* log) const {
  LightSample ls = sample_light(sp, frame, rng, counts, log);
  LayeredScatter s;
  if (mt.stack.response) {
    s = layered_table_scatter(mt, wo, ls, t_.light_shape, p, rng);
  } else if (mt.stack.volume) {
    const StackPointFactors fac = stack_point_factors(mt.stack, scene_.textures, sp.uv);
    VolumeWalkContext ctx;
    ctx.materials = &t_.materials;
    ctx.material = sp.material;
    ctx.textures = &scene_.textures;
    ctx.uv = sp.uv;
    const int base = embree_.info(hit.geom).material;
    std::optional<TangentPlaneRegions> under;
    if (base >= 0 && scene_.materials[base].dispatches()) {
      under.emplace(scene_, base, sp, frame, embree_.uv_gradient(hit));
      ctx.under = &*under;
    }
    s = layered_scatter(mt, fac, wo, ls, t_.light_shape, t_.n, p, rng, &ctx);
  } else {
    const StackPointFactors fac = stack_point_factors(mt.stack, scene_.textures, sp.uv);
    s = layered_scatter(mt, fac, wo, ls, t_.light_shape, t_.n, p, rng);
  }
  Continuation c;
  if (!s.ok) return c;
  glm::dvec3 wi_w = frame.to_world(s.wi);
  if (glm::dot(wi_w, sp.ng) <= 0) return c;
  c.ok = true;
  c.wi_world = wi_w;
  c.pdf = s.pdf;
  c.diffuse = !s.reflected;
  return c;
}

PathTracer::Continuation PathTracer::spatial_vertex(const SurfacePoint& sp, unsigned geom, const Frame& frame,
                                                    const glm::dvec3& wo, const MaterialTables& mt, PathLanes& p, Rng& rng,
                                                    RayCounts& counts, RayLog* log) const {
  const SpatialScatter s = spatial_.scatter(sp, geom, frame, wo, mt, p, rng, counts, log);
  Continuation c;
  if (!s.ok || glm::dot(s.wi_world, s.from.ng) <= 0) return c;
  c.ok = true;
  c.wi_world = s.wi_world;
  c.pdf = s.pdf;
  c.diffuse = !s.reflected;
  c.moved = !s.reflected;
  c.from = s.from;
  c.light_by_power = true;  // its next-event estimation chooses LEDs by power (spatial_vertex.cpp)
  return c;
}

bool PathTracer::roulette(PathLanes& p, int depth, Rng& rng) const {
  float maxb = 0;
  for (int k = 0; k < kLanes; ++k) maxb = std::max(maxb, p.beta[k]);
  if (maxb <= 0) return false;
  if (depth + 1 >= scene_.integrator.rr_start_depth) {
    float q = std::min(1.0f, maxb);
    if (q < 1.0f) {
      if (rng.next_float() >= q) return false;
      for (int k = 0; k < kLanes; ++k) p.beta[k] /= q;
    }
  }
  return true;
}

double PathTracer::splat(const PathLanes& p, double* bands, double* fluorescence) const {
  double total = 0;
  for (int k = 0; k < kLanes; ++k) {
    if (p.L[k] == 0) continue;
    const int f = p.film[k];
    double v = double(p.L[k]) * t_.film_scale[f] / kLanes;
    double vf = double(p.Lf[k]) * t_.film_scale[f] / kLanes;
    for (int j = film_first_[f]; j < film_first_[f + 1]; ++j) {
      const RenderTables::BandWeight& bw = film_bw_[j];
      bands[bw.band] += bw.weight * v;
      total += bw.weight * v;
      if (fluorescence) fluorescence[bw.band] += bw.weight * vf;
    }
  }
  return total;
}

double PathTracer::sample_pixel(int x, int y, Rng& rng, double* bands, RayCounts& counts, RayLog* log,
                                double* fluorescence) const {
  counts.start();
  PathLanes p;
  init_lanes(p, rng);
  Ray ray = camera_ray(x, y, rng);
  counts.camera++;
  counts.mark(Stage::kCamera);
  double prev_pdf = 0;        // solid-angle pdf of the direction that produced `ray`, 0 = camera/delta
  SurfacePoint prev;          // the point `ray` left (when prev_pdf > 0)
  bool prev_by_power = false; // that point's next-event estimation chose its LED by power alone
  bool diffuse_seen = false;  // the path has left a surface through its diffuse lobe
  const int max_depth = scene_.integrator.max_depth;
  for (int depth = 0;; ++depth) {
    record_ray(log, ray.o, ray.d, 1e30f, false);
    RayHit hit = embree_.intersect(ray.o, ray.d);
    counts.mark(Stage::kIntersect);
    if (!hit.found()) break;
    if (embree_.info(hit.geom).kind == GeomInfo::Kind::kLed) {
      hit_led(hit, ray, prev_pdf, prev, prev_by_power, p);
      counts.mark(Stage::kShading);
      break;  // the LED body absorbs
    }
    SurfacePoint sp = embree_.surface(hit, ray.o, ray.d);
    glm::dvec3 wo_w = -ray.d;
    // Two-sided surfaces: work on the side the ray came from.
    if (glm::dot(sp.ng, wo_w) < 0) { sp.ng = -sp.ng; sp.ns = -sp.ns; sp.flipped = true; }
    if (glm::dot(sp.ns, wo_w) <= 1e-6) sp.ns = sp.ng;
    const MaterialTables& mt = t_.materials[sp.material];
    if (!mt.emission.empty())
      for (int k = 0; k < kLanes; ++k) p.add(k, p.beta[k] * mt.emission[p.wl[k]]);
    if (depth >= max_depth) break;

    Frame frame(sp.ns);
    glm::dvec3 wo = frame.to_local(wo_w);
    counts.mark(Stage::kSurface);
    Continuation c = !mt.stack.enabled ? surface_vertex(sp, frame, wo, mt, diffuse_seen, p, rng, counts, log)
                     : mt.stack.spatial ? spatial_vertex(sp, hit.geom, frame, wo, mt, p, rng, counts, log)
                                        : layered_vertex(sp, hit, frame, wo, mt, p, rng, counts, log);
    counts.mark(mt.stack.enabled ? Stage::kLayered : Stage::kShading);
    if (!c.ok) break;
    if (depth + 1 >= max_depth && !hittable_emitters_) break;  // the next hit could only add emission
    if (c.diffuse) diffuse_seen = scene_.integrator.regularize_glossy > 0;
    prev_pdf = c.pdf;
    prev = c.moved ? c.from : sp;
    prev_by_power = c.light_by_power;
    const glm::dvec3 next_o = EmbreeScene::offset(prev, c.wi_world);
    if (embree_.leaves_scene(next_o, c.wi_world)) break;  // it could hit nothing (no light from outside)
    const bool more = roulette(p, depth, rng);
    counts.mark(Stage::kShading);
    if (!more) break;
    ray = {next_o, c.wi_world};
    counts.extension++;
  }
  counts.mark(Stage::kSurface);  // a path that ends at a hit ends after its hit point and material
  const double total = splat(p, bands, fluorescence);
  counts.mark(Stage::kFilm);
  return total;
}

}  // namespace ofl
