// Shared by tests/test_layered_table.cpp and benchmarks/layered_table_check.cpp: a one-material
// scene's render tables (the material's stack tables are what both examine), directions from a
// cosine and an azimuth, and a running mean with its standard error.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>

#include <glm/vec3.hpp>

#include "renderer/render/integrator/render_tables.h"
#include "renderer/scene/scene.h"

namespace ofl::test {

struct Bench {
  Scene scene;
  std::unique_ptr<RenderTables> tables;
  const MaterialTables& mt() const { return tables->materials[0]; }
  int bin(double nm) const { return scene.grid().index_of(nm); }
};

// Unit vector with z = mu at azimuth phi.
inline glm::dvec3 direction(double mu, double phi) {
  double s = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  return {s * std::cos(phi), s * std::sin(phi), mu};
}

struct Mean {
  double s1 = 0, s2 = 0;
  long long n = 0;
  void add(double v) { s1 += v; s2 += v * v; ++n; }
  double mean() const { return n ? s1 / n : 0; }
  double se() const { return n ? std::sqrt(std::max(0.0, s2 / n - mean() * mean()) / n) : 0; }
};

}  // namespace ofl::test
