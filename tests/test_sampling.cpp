// Chi-square tests of the sampling routines against their densities (docs/transport.md, "How it is checked").
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "materials/interfaces/coated.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/trace/sampling.h"
#include "tests/stat_utils.h"

using namespace ofl;

namespace {
constexpr int kThetaBins = 16, kPhiBins = 32;

// Bins directions on the hemisphere by (cos theta, phi) and compares with a pdf integrated per bin
// by a fine midpoint rule.
template <class Sample, class Pdf>
test::ChiSquare hemisphere_test(Sample sample, Pdf pdf, int n) {
  std::vector<double> obs(kThetaBins * kPhiBins, 0.0), exp(kThetaBins * kPhiBins, 0.0);
  Rng rng(7, 11);
  for (int i = 0; i < n; ++i) {
    glm::dvec3 w = sample(rng.next_double(), rng.next_double());
    if (w.z <= 0) continue;
    int t = std::min(kThetaBins - 1, int(w.z * kThetaBins));
    double phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * kPi;
    int p = std::min(kPhiBins - 1, int(phi / (2 * kPi) * kPhiBins));
    obs[t * kPhiBins + p] += 1;
  }
  const int sub = 8;
  for (int t = 0; t < kThetaBins; ++t)
    for (int p = 0; p < kPhiBins; ++p) {
      double s = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          double mu = (t + (a + 0.5) / sub) / kThetaBins;
          double phi = (p + (b + 0.5) / sub) / kPhiBins * 2 * kPi;
          double st = std::sqrt(1 - mu * mu);
          s += pdf(glm::dvec3(st * std::cos(phi), st * std::sin(phi), mu));
        }
      // d omega = d mu d phi
      exp[t * kPhiBins + p] = n * s / (sub * sub) * (1.0 / kThetaBins) * (2 * kPi / kPhiBins);
    }
  return test::chi_square(obs, exp);
}
}  // namespace

TEST(Sampling, CosineHemisphereMatchesPdf) {
  auto r = hemisphere_test([](double a, double b) { return sample_cosine_hemisphere(a, b); },
                           [](const glm::dvec3& w) { return cosine_hemisphere_pdf(w.z); }, 400000);
  EXPECT_GT(r.p_value, 1e-4) << "chi2 " << r.statistic << " dof " << r.dof;
}

TEST(Sampling, ChiSquareRejectsAWrongPdf) {
  // The same samples against the uniform-hemisphere pdf must fail: the test has power.
  auto r = hemisphere_test([](double a, double b) { return sample_cosine_hemisphere(a, b); },
                           [](const glm::dvec3&) { return 1.0 / (2 * kPi); }, 400000);
  EXPECT_LT(r.p_value, 1e-6);
}

TEST(Sampling, ConcentricDiskIsUniform) {
  const int n = 200000, g = 20;
  std::vector<double> obs(g * g, 0.0), exp(g * g, 0.0);
  Rng rng(3, 5);
  for (int i = 0; i < n; ++i) {
    glm::dvec2 p = sample_concentric_disk(rng.next_double(), rng.next_double());
    ASSERT_LE(p.x * p.x + p.y * p.y, 1.0 + 1e-12);
    int x = std::min(g - 1, int((p.x + 1) / 2 * g)), y = std::min(g - 1, int((p.y + 1) / 2 * g));
    obs[y * g + x] += 1;
  }
  const int sub = 32;
  for (int y = 0; y < g; ++y)
    for (int x = 0; x < g; ++x) {
      int inside = 0;
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          double px = -1 + 2.0 * (x + (a + 0.5) / sub) / g, py = -1 + 2.0 * (y + (b + 0.5) / sub) / g;
          inside += px * px + py * py <= 1;
        }
      exp[y * g + x] = n * (double(inside) / (sub * sub)) * (4.0 / (g * g)) / kPi;
    }
  auto r = test::chi_square(obs, exp);
  EXPECT_GT(r.p_value, 1e-4) << "chi2 " << r.statistic << " dof " << r.dof;
}

TEST(Sampling, DiscreteDistribution) {
  std::vector<double> w = {0.5, 0, 3, 1, 0.25, 2, 0, 7};
  DiscreteDistribution d(w);
  double sum = 0;
  for (double v : w) sum += v;
  std::vector<double> obs(w.size(), 0.0), exp(w.size());
  Rng rng(1, 2);
  const int n = 100000;
  for (int i = 0; i < n; ++i) obs[d.sample(rng.next_double())] += 1;
  for (size_t i = 0; i < w.size(); ++i) {
    exp[i] = n * w[i] / sum;
    EXPECT_DOUBLE_EQ(d.pdf(int(i)), w[i] / sum);
    if (w[i] == 0) {
      EXPECT_EQ(obs[i], 0);
    }
  }
  EXPECT_GT(test::chi_square(obs, exp).p_value, 1e-4);
}

// The guide table changes how the bin is found, not which: the same bin as the binary search for
// random u, for u at and next to every CDF entry (where rounding could send the guide astray), with
// zero-weight bins, one bin, and guides of 1, 4, 16 (the renderer's) and 64 entries per bin.
TEST(Sampling, GuidedSamplerGivesTheBinarySearchBin) {
  const std::vector<std::vector<double>> cases = {
      {0.5, 0, 3, 1, 0.25, 2, 0, 7}, {1}, {0, 0, 1, 0}, {1e-9, 1, 1e-9, 0, 0, 5, 1e-12}};
  Rng rng(4, 8);
  for (const auto& w : cases)
    for (int per_bin : {1, 4, 16, 64}) {
      DiscreteDistribution d(w);
      GuidedSampler g(d, per_bin);
      std::vector<double> us = {0.0, 0.5, 1.0 - 1e-16};
      for (double c : d.cdf)
        for (double u : {c, std::nextafter(c, 0.0), std::nextafter(c, 1.0)})
          if (u >= 0 && u < 1) us.push_back(u);
      for (int i = 0; i < 100000; ++i) us.push_back(rng.next_double());
      for (double u : us) ASSERT_EQ(g.sample(u), d.sample(u)) << "u " << u << " per_bin " << per_bin;
    }
}

class GgxSampling : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(GgxSampling, VisibleNormalSamplingMatchesPdf) {
  auto [alpha, mu_o] = GetParam();
  GgxCoating c;
  c.ior = 1.33;
  c.alpha = alpha;
  glm::dvec3 wo(std::sqrt(1 - mu_o * mu_o), 0, mu_o);
  // Reflected directions can go below the horizon; those are rejected by the renderer, so the
  // density on the upper hemisphere integrates to less than one and the test bins only z > 0.
  auto r = hemisphere_test([&](double a, double b) { return c.sample(wo, a, b); },
                           [&](const glm::dvec3& w) { return c.pdf(wo, w); }, 400000);
  EXPECT_GT(r.p_value, 1e-4) << "alpha " << alpha << " mu_o " << mu_o << " chi2 " << r.statistic << " dof " << r.dof;
}

INSTANTIATE_TEST_SUITE_P(Coated, GgxSampling,
                         ::testing::Values(std::make_tuple(0.15, 0.9), std::make_tuple(0.3, 0.5), std::make_tuple(0.6, 0.2)));
