// Light selection by what an LED can give a point (renderer/render/trace/light_choice.h): the choice is
// unbiased only if every LED that can light a point has a positive probability there. Checked
// against brute force over points of the emitting disk, against the closed-form irradiance of a
// point LED, and by a chi-square test of the choice against its probabilities; the indexed profile
// table against a plain binary search.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdio>

#include <glm/geometric.hpp>

#include "renderer/validation/harness/bench_support.h"
#include "renderer/render/trace/light_choice.h"
#include "renderer/render/trace/rng.h"
#include "renderer/spectral/spectra/units.h"
#include "tests/stat_utils.h"

using namespace ofl;

namespace {

// pbrt-v4's spot shape on a 0.1 degree table: 1 inside `inner`, smoothstep in cos down to 0 at `outer`.
LedProfile spot_table(double inner_deg, double outer_deg) {
  LedProfile p;
  const double ci = std::cos(inner_deg * kPi / 180), co = std::cos(outer_deg * kPi / 180);
  for (int i = 900; i >= 0; --i) {
    const double a = i * 0.1 * kPi / 180, c = std::cos(a);
    const double t = std::clamp((c - co) / (ci - co), 0.0, 1.0);
    p.table_cos.push_back(c);
    p.table_value.push_back(t * t * (3 - 2 * t));
  }
  p.index_table();
  return p;
}

// A profile with a bump away from the axis (not monotone): zero to 20 deg, 1 at 40 deg, zero past 60.
LedProfile ring_table() {
  LedProfile p;
  for (int i = 90; i >= 0; --i) {
    const double a = double(i);
    p.table_cos.push_back(std::cos(a * kPi / 180));
    p.table_value.push_back(a == 0 ? 1.0 : std::max(0.0, 1 - std::fabs(a - 40) / 20));
  }
  p.index_table();
  return p;
}

glm::dvec3 random_unit(Rng& r) {
  const double z = 1 - 2 * r.next_double(), phi = 2 * kPi * r.next_double(), s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

LedLight make_led(const glm::dvec3& pos, const glm::dvec3& axis, double radius, const LedProfile& prof) {
  LedLight l;
  l.position = pos;
  l.axis = glm::normalize(axis);
  glm::dvec3 helper = std::fabs(l.axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  l.tangent = glm::normalize(glm::cross(helper, l.axis));
  l.bitangent = glm::cross(l.axis, l.tangent);
  l.radius_m = radius;
  l.profile = prof;
  l.intensity_W_sr = 0.7;
  return l;
}

// Does some point of the LED's disk light p (the conditions under which the tracer's light sample
// is nonzero: in front of the emitter, profile positive, above both normals)?
bool some_point_lights(const LedLight& l, const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng, Rng& r, int tries) {
  for (int i = 0; i < tries; ++i) {
    glm::dvec3 q = l.position;
    if (!l.is_point()) {
      glm::dvec2 d = sample_concentric_disk(r.next_double(), r.next_double()) * l.radius_m;
      q += d.x * l.tangent + d.y * l.bitangent;
    }
    const glm::dvec3 w = glm::normalize(q - p);
    const double cl = -glm::dot(w, l.axis);
    if (cl > 0 && l.profile.eval(cl) > 0 && glm::dot(w, ns) > 0 && glm::dot(w, ng) > 0) return true;
    if (l.is_point()) return false;
  }
  return false;
}

}  // namespace

TEST(LedProfileTable, IndexedLookupEqualsBinarySearch) {
  for (const LedProfile& indexed : {spot_table(30, 35), ring_table()}) {
    LedProfile plain = indexed;
    plain.table_start.clear();
    plain.table_envelope.clear();
    Rng r(3, 5);
    for (int i = 0; i < 200000; ++i) {
      const double c = i < 1000 ? indexed.table_cos[i % indexed.table_cos.size()] : 2 * r.next_double() - 1;
      ASSERT_EQ(indexed.eval(c), plain.eval(c)) << "cos " << c;
    }
  }
}

TEST(LedProfileTable, MaxBeyondBoundsEveryLargerAngle) {
  for (const LedProfile& p : {spot_table(30, 35), ring_table()}) {
    Rng r(9, 2);
    for (int i = 0; i < 20000; ++i) {
      const double c = 2 * r.next_double() - 1, c2 = -1 + (c + 1) * r.next_double();  // c2 <= c
      EXPECT_GE(p.max_beyond(c), p.eval(c2)) << c << " " << c2;
    }
    // Zero beyond the support: the spot has none past 35 degrees, the ring none past 60.
    EXPECT_EQ(p.max_beyond(std::cos(61.0 * kPi / 180)), 0.0);
  }
  LedProfile cosm;
  cosm.cos_power = 7.3;
  EXPECT_DOUBLE_EQ(cosm.max_beyond(0.8), std::pow(0.8, 7.3));
  EXPECT_EQ(cosm.max_beyond(-0.1), 0.0);
}

// The cos^m profile's bound for light selection, read from a table instead of computed with pow:
// never below c^m (closed form), positive wherever c^m is (even for a power steep enough that the
// table's low cosines underflow), within (1 + 1 / bins)^m of it where c >= 1/2, and the exact
// value again once cos_power changes after the table was made.
TEST(LedProfileTable, ChoiceBoundOfAPowerIsATightBound) {
  Rng r(5, 3);
  const double N = LedProfile::kPowerBoundBins;
  for (double m : {0.0, 1.0, 4.8, 57.0, 1e4}) {
    LedProfile p;
    p.cos_power = m;
    p.index_table();
    for (int i = 0; i < 20000; ++i) {
      const double c = 1.2 * r.next_double() - 0.2, exact = c > 0 ? std::pow(c, m) : 0.0;
      const double b = p.choice_bound(c);
      ASSERT_GE(b, exact) << "m " << m << " cos " << c;
      if (exact > 0) ASSERT_GT(b, 0.0) << "m " << m << " cos " << c;
      if (c <= 0) ASSERT_EQ(b, 0.0);
      if (c >= 0.5 && m < 100) ASSERT_LE(b, exact * std::pow(1.0 + 1.0 / (N * c), m) * (1 + 1e-12)) << "m " << m << " cos " << c;
    }
    EXPECT_EQ(p.choice_bound(1.0), 1.0);
  }
  LedProfile p;
  p.cos_power = 3.0;
  p.index_table();
  p.cos_power = 7.3;  // changed after the table: the bound is the exact power again
  EXPECT_DOUBLE_EQ(p.choice_bound(0.8), std::pow(0.8, 7.3));
}

TEST(LedProfileTable, ZeroAtOrBelowItsSupport) {
  LedProfile p = spot_table(30, 35);
  EXPECT_NEAR(p.zero_at_or_below, std::cos(35 * kPi / 180), 1e-12);
  Rng r(4, 4);
  for (int i = 0; i < 10000; ++i) EXPECT_EQ(p.eval(-1 + (p.zero_at_or_below + 1) * r.next_double()), 0.0);
  EXPECT_EQ(p.eval(p.zero_at_or_below), 0.0);
  EXPECT_GT(p.eval(std::cos(34.95 * kPi / 180)), 0.0);
  EXPECT_NEAR(ring_table().zero_at_or_below, 0.5, 1e-12);  // nothing past 60 degrees
}

// A point LED's weight is its unoccluded irradiance: I0 P(theta) cos(theta_s) / r^2.
TEST(LightChoice, PointLedWeightIsItsIrradiance) {
  LedLight l = make_led({0.01, 0.02, 0.05}, {0.2, -0.1, -1}, 0, spot_table(30, 35));
  const glm::dvec3 n(0, 0, 1);
  for (glm::dvec3 p : {glm::dvec3(0, 0, 0), glm::dvec3(0.02, 0.03, 0), glm::dvec3(-0.03, 0.01, 0.0)}) {
    const glm::dvec3 to = l.position - p;
    const double r2 = glm::dot(to, to);
    const glm::dvec3 w = to / std::sqrt(r2);
    const double expect = 0.7 * l.profile.eval(-glm::dot(w, l.axis)) * w.z / r2;
    EXPECT_NEAR(l.irradiance_bound(p, n, n), expect, 1e-12 * (1 + expect));
  }
  EXPECT_EQ(l.irradiance_bound({0, 0, 0.1}, n, n), 0.0);  // behind the LED
  EXPECT_EQ(l.irradiance_bound({0, 0, 0}, -n, -n), 0.0);  // below the surface
}

// The property that keeps the estimate unbiased: wherever some point of an LED can light a
// surface point, that LED's weight there is positive. Random points, normals and LEDs of every
// kind (point and disk; cos^m, a cut-off spot, a profile that is zero from 1 to 20 degrees off its axis).
TEST(LightChoice, PositiveWhereverTheLedCanLight) {
  LedProfile cosm;
  cosm.cos_power = 4;
  const LedProfile profiles[] = {cosm, spot_table(20, 25), ring_table()};
  Rng r(21, 4);
  int lit = 0, unlit = 0;
  for (int i = 0; i < 20000; ++i) {
    const LedProfile& prof = profiles[i % 3];
    const double radius = (i / 3) % 2 ? 0.0 : 0.002 + 0.01 * r.next_double();
    LedLight l = make_led(0.03 * random_unit(r), random_unit(r), radius, prof);
    const glm::dvec3 p = 0.03 * random_unit(r) * r.next_double();
    glm::dvec3 ng = random_unit(r), ns = glm::normalize(ng + 0.5 * random_unit(r));
    if (glm::dot(ns, ng) < 0) ns = -ns;
    const double w = l.irradiance_bound(p, ns, ng);
    ASSERT_GE(w, 0.0);
    if (some_point_lights(l, p, ns, ng, r, 400)) {
      ++lit;
      ASSERT_GT(w, 0.0) << "LED " << i << " lights the point but has weight 0";
    } else if (w == 0) {
      ++unlit;
    }
  }
  // Both kinds of point occur, and most points no LED can light get weight 0 (no shadow ray).
  EXPECT_GT(lit, 2000) << unlit;
  EXPECT_GT(unlit, 8000) << lit;
}

// The choice follows its probabilities (chi-square), and pmf() repeats pick()'s probability.
TEST(LightChoice, PickFollowsItsProbabilities) {
  std::vector<LedLight> lights = {make_led({0.02, 0, 0.04}, {-0.3, 0, -1}, 0, spot_table(30, 35)),
                                  make_led({-0.02, 0, 0.04}, {0.3, 0, -1}, 0.003, spot_table(25, 30)),
                                  make_led({0, 0.03, 0.02}, {0, -1, 0.114}, 0, ring_table()),
                                  make_led({0, 0, -0.05}, {0, 0, -1}, 0.002, spot_table(30, 35))};  // below: never
  DiscreteDistribution by_power({1, 1, 1, 1});
  LightChoice choice(lights, by_power);
  const glm::dvec3 p(0.004, -0.002, 0), n(0, 0, 1);
  std::vector<double> pmf, obs(lights.size(), 0.0), exp;
  double sum = 0;
  for (size_t i = 0; i < lights.size(); ++i) sum += pmf.emplace_back(choice.pmf(int(i), p, n, n));
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_EQ(pmf[3], 0.0);
  Rng r(1, 1);
  const int N = 200000;
  for (int i = 0; i < N; ++i) {
    LightPick k = choice.pick(p, n, n, r.next_double());
    ASSERT_GE(k.light, 0);
    ASSERT_EQ(k.pmf, pmf[k.light]);
    obs[k.light] += 1;
  }
  for (double q : pmf) exp.push_back(N * q);
  EXPECT_GT(test::chi_square(obs, exp).p_value, 1e-3);
  // No LED can light a point under the floor facing down: no choice at all.
  EXPECT_EQ(choice.pick({0, 0, -0.01}, -n, -n, 0.5).light, -1);
}

namespace {

// Per seed, the image means over three bands of rows (0-10, 11-21, 22-31) and every output band.
std::vector<std::array<double, 3>> region_means(const std::string& selection, int seeds) {
  using nlohmann::json;
  std::vector<std::array<double, 3>> out;
  for (int s = 1; s <= seeds; ++s) {
    BenchOptions o{8, uint64_t(100 + s), false, "", selection};
    json j = bench::base_scene(o, 100000);
    j["camera"] = {{"position", {0, 0, 0}}, {"look_at", {1, 0.4, 0.1}}, {"up", {0, 0, 1}}, {"fov_deg", 100}, {"resolution", {32, 32}}};
    j["materials"] = {{"wall", {{"type", "lambertian"}, {"reflectance", 0.7}}}};
    j["geometry"] = {{{"type", "sphere"}, {"center", {0, 0, 0}}, {"radius", 1.0}, {"material", "wall"}}};
    auto spot = [](double inner, double outer) {
      json rows = json::array();
      for (int i = 0; i <= 180; ++i) {
        const double a = i * 0.5, t = std::clamp((outer - a) / (outer - inner), 0.0, 1.0);
        rows.push_back({a, t * t * (3 - 2 * t)});
      }
      return json{{"table", rows}};
    };
    j["lights"] = {
        {{"type", "led"}, {"spd", 1.0}, {"radiant_intensity_W_sr", 1.0}, {"profile", spot(20, 25)}, {"position", {0.2, 0, 0}}, {"axis", {1, 0.3, 0}}},
        {{"type", "led"}, {"spd", {{"type", "blackbody"}, {"temperature_K", 3000}}}, {"radiant_intensity_W_sr", 0.5},
         {"profile", {{"half_angle_deg", 40}}}, {"radius_m", 0.05}, {"position", {-0.3, 0.1, 0}}, {"axis", {-1, 0, 0.2}}},
        {{"type", "led"}, {"spd", 1.0}, {"radiant_intensity_W_sr", 0.8}, {"profile", spot(10, 14)}, {"position", {0, -0.4, 0.3}}, {"axis", {0.5, 1, -0.2}}}};
    bench::Rendered r = bench::render_json(j, "light_choice_" + selection);
    const SpectralImage& img = r.result.image;
    std::array<double, 3> m{};
    for (int k = 0; k < 3; ++k) {
      const int y0 = k * 11, y1 = std::min(32, (k + 1) * 11);
      double sum = 0;
      int n = 0;
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < img.width; ++x)
          for (int b = 0; b < img.bands(); ++b, ++n) sum += img.data[(size_t(y) * img.width + x) * img.bands() + b];
      m[k] = sum / n;
    }
    out.push_back(m);
  }
  return out;
}

}  // namespace

// The choice by reach against the older choice by power on one scene, within their noise: a closed
// white-ish sphere (many bounces, Russian roulette) lit by two spots and a disk LED that faces away
// from most of the wall (its MIS with continuation rays that hit it uses the choice's probability
// at the point they left). Image means over three bands of rows, 8 seeds each: Welch's t below 4.
TEST(LightChoice, AgreesWithChoiceByPowerWithinNoise) {
  const int seeds = 8;
  const auto a = region_means("reach", seeds), b = region_means("power", seeds);
  auto mv = [](const std::vector<std::array<double, 3>>& v, int k) {
    double m = 0, s = 0;
    for (const auto& x : v) m += x[k];
    m /= v.size();
    for (const auto& x : v) s += (x[k] - m) * (x[k] - m);
    return std::pair{m, s / (v.size() - 1) / v.size()};  // mean and its variance
  };
  for (int k = 0; k < 3; ++k) {
    const auto [ma, va] = mv(a, k);
    const auto [mb, vb] = mv(b, k);
    const double t = (ma - mb) / std::sqrt(va + vb);
    std::printf("rows %d: reach %.5g +- %.2g, power %.5g +- %.2g, t = %.2f\n", k, ma, std::sqrt(va), mb, std::sqrt(vb), t);
    EXPECT_LT(std::fabs(t), 4.0);
    EXPECT_GT(ma, 0.0);
  }
}
