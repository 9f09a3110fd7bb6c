// The independent forward photon Monte Carlo (renderer/validation/references/forward_mc.h), the
// reference of the lesion-disc bench cases, against closed forms of radiative transfer: a
// semi-infinite isotropic scatterer of albedo w with no index step (n = 1 everywhere), lit by a
// normal pencil beam, integrated over the surface (equal to uniform light):
// - its total diffuse reflectance is 1 - sqrt(1 - w) H(1),
// - its radiance factor straight up is pi L / E = w H(1)^2 / 8 (Chandrasekhar's reflection
//   function at mu = mu0 = 1),
// with H Chandrasekhar's H-function for isotropic scattering, solved here by iterating its
// integral equation on a Gauss-Legendre grid. The second is what the local estimate of the light
// leaving along the normal must give; the cone tallies must give the first.
// And with an index step at the top (n = 1.4): the local estimate against the narrowest cone
// tally of the same photons, both estimates of light leaving close to the normal.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "renderer/validation/references/forward_mc.h"

using namespace ofl;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Gauss-Legendre nodes and weights on [0, 1] (Newton on the Legendre polynomial).
void gauss_legendre01(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(n, 0);
  w.assign(n, 0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[i] = 0.5 * (1 - z);
    w[i] = 1.0 / ((1 - z * z) * dp * dp);  // 2 / ((1 - z^2) P'^2), halved for [0, 1]
  }
}

// H(mu) for isotropic scattering of albedo w: 1 / H(mu) = 1 - (w / 2) mu int_0^1 H(t) / (mu + t) dt.
// Also checks the solution's zeroth moment against its closed form (2 / w)(1 - sqrt(1 - w)).
double chandrasekhar_h(double w, double mu) {
  std::vector<double> x, q;
  gauss_legendre01(96, x, q);
  std::vector<double> h(x.size(), 1.0);
  auto integral = [&](double m) {
    double s = 0;
    for (size_t j = 0; j < x.size(); ++j) s += q[j] * h[j] / (m + x[j]);
    return s;
  };
  for (int it = 0; it < 2000; ++it) {
    std::vector<double> next(x.size());
    double change = 0;
    for (size_t i = 0; i < x.size(); ++i) {
      next[i] = 1.0 / (1.0 - 0.5 * w * x[i] * integral(x[i]));
      change = std::max(change, std::abs(next[i] - h[i]));
    }
    h = next;
    if (change < 1e-13) break;
  }
  double h0 = 0;
  for (size_t j = 0; j < x.size(); ++j) h0 += q[j] * h[j];
  EXPECT_NEAR(h0, 2.0 / w * (1.0 - std::sqrt(1.0 - w)), 1e-6) << "H-function moment, albedo " << w;
  return 1.0 / (1.0 - 0.5 * w * mu * integral(mu));
}

// One wavelength bin, one semi-infinite layer of index n (ambient 1), isotropic scattering.
StackTables isotropic_half_space(double albedo, double n) {
  StackTables st;
  st.ambient_ior = 1;
  st.bottom = StackBottom::kSemiInfinite;
  StackLayerTables L;
  L.top = 0;
  L.bottom = std::numeric_limits<double>::infinity();
  L.ior = n;
  L.g = 0;
  L.mus = {float(10.0 * albedo)};
  L.mua = {float(10.0 * (1.0 - albedo))};
  st.layers.push_back(L);
  return st;
}

struct Estimate {
  double mean = 0, se = 0;
};

// Mean and standard error over independent batches of pick(tally) / photons.
template <class Pick>
std::vector<Estimate> batch_estimates(const ForwardSetup& s, long long photons, int batches, int quantities, Pick pick) {
  std::vector<double> sum(quantities, 0), sum2(quantities, 0);
  for (int b = 0; b < batches; ++b) {
    const ForwardTally t = run_forward_mc(s, photons, 1000 + b);
    for (int q = 0; q < quantities; ++q) {
      const double v = pick(t, q) / double(t.photons);
      sum[q] += v;
      sum2[q] += v * v;
    }
  }
  std::vector<Estimate> out(quantities);
  for (int q = 0; q < quantities; ++q) {
    out[q].mean = sum[q] / batches;
    out[q].se = std::sqrt(std::max(0.0, sum2[q] / batches - out[q].mean * out[q].mean) / (batches - 1));
  }
  return out;
}

ForwardSetup pencil(const StackTables& st) {
  ForwardSetup s;
  s.outside.st = &st;
  s.n = 1;
  s.source = {1.0};
  s.fluorescence = false;
  s.ring_edges = {0.0, 1e9};
  s.narrow_cos = 0.97;
  return s;
}

}  // namespace

TEST(ForwardMonteCarlo, HalfSpaceMatchesChandrasekhar) {
  for (double w : {0.5, 0.9, 0.99}) {
    const StackTables st = isotropic_half_space(w, 1.0);
    const ForwardSetup s = pencil(st);
    const auto e = batch_estimates(s, 20000, 10, 2, [](const ForwardTally& t, int q) { return q == 0 ? t.elastic[0] : t.elastic_normal[0]; });
    const double h1 = chandrasekhar_h(w, 1.0);
    const double rd = 1.0 - std::sqrt(1.0 - w) * h1, rf = w * h1 * h1 / 8.0;
    std::printf("albedo %.2f: Rd %.5f +- %.5f (closed form %.5f), pi L / E along the normal %.5f +- %.5f (%.5f)\n", w, e[0].mean,
                e[0].se, rd, kPi * e[1].mean, kPi * e[1].se, rf);
    // Independent batches: 3.5 standard errors of the mean.
    EXPECT_NEAR(e[0].mean, rd, 3.5 * e[0].se) << "albedo " << w << ": diffuse reflectance";
    EXPECT_NEAR(kPi * e[1].mean, rf, 3.5 * kPi * e[1].se) << "albedo " << w << ": radiance factor along the normal";
    // The test can tell: the estimates are tight enough to see a 3 % error.
    EXPECT_LT(3.5 * kPi * e[1].se, 0.03 * rf) << "albedo " << w;
    EXPECT_LT(3.5 * e[0].se, 0.03 * rd) << "albedo " << w;
  }
}

// With an index step at the top the light inside is refracted and partly reflected back; the local
// estimate and the photons counted within 14 degrees of the normal (weight over the cone's projected
// solid angle, pi (1 - c^2)) see the same radiance near the normal.
TEST(ForwardMonteCarlo, NormalEstimateMatchesNarrowCone) {
  const StackTables st = isotropic_half_space(0.95, 1.4);
  const ForwardSetup s = pencil(st);
  const double c = s.narrow_cos;
  const auto e = batch_estimates(s, 40000, 10, 2, [&](const ForwardTally& t, int q) {
    return q == 0 ? t.elastic_narrow[0] / (kPi * (1.0 - c * c)) : t.elastic_normal[0];
  });
  std::printf("n 1.4: pi L / E along the normal %.5f +- %.5f, within 14 degrees %.5f +- %.5f\n", kPi * e[1].mean, kPi * e[1].se,
              kPi * e[0].mean, kPi * e[0].se);
  EXPECT_NEAR(e[1].mean, e[0].mean, 3.5 * std::hypot(e[0].se, e[1].se));
  // The local estimate is the sharper of the two (it gains from every scattering, not 6 % of exits).
  EXPECT_LT(e[1].se, 0.5 * e[0].se);
  // And the index step matters: the radiance is not that of the matched half-space.
  const double h1 = chandrasekhar_h(0.95, 1.0);
  EXPECT_GT(std::abs(kPi * e[1].mean - 0.95 * h1 * h1 / 8.0), 10 * kPi * e[1].se);
}
