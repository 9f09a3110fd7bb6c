// Writes the shipped camera example of `oralfluor diagnose` (assets/measurements/camera_example/
// patches.csv and radiance.csv): the Macbeth chart under 3000 K and 5000 K blackbody light seen by
// the MT9V024 behind the Largan IR-cut filter, two captures per patch, with a hidden 3x3 channel
// crosstalk (seed 7). Deterministic; rerun to regenerate:
//   build/diagnose_make_camera_example assets/measurements/camera_example
#include <cstdio>
#include <map>
#include <sstream>
#include <string>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "tests/support/synthetic.h"

using namespace ofl;

namespace {

int run(int argc, char** argv) {
  std::string dir = argc > 1 ? argv[1] : "assets/measurements/camera_example";
  SyntheticCameraOptions o;
  o.seed = 7;
  o.effect = "crosstalk";
  SyntheticCamera s = make_synthetic_camera(o);
  // One radiance column per patch and illuminant (captures share the measured spectrum).
  std::map<std::string, const CameraPatch*> columns;
  for (auto& p : s.data.patches) columns.emplace(p.id + "_" + p.conditions.at("illuminant"), &p);
  std::ostringstream r;
  r << "wavelength_nm";
  for (auto& [name, p] : columns) r << "," << name;
  r << "\n";
  const auto& nm = columns.begin()->second->nm;
  for (size_t k = 0; k < nm.size(); ++k) {
    r << nm[k];
    for (auto& [name, p] : columns) {
      char b[32];
      std::snprintf(b, sizeof b, "%.6g", p->radiance[k]);
      r << "," << b;
    }
    r << "\n";
  }
  write_file_atomic(dir + "/radiance.csv", r.str());
  std::ostringstream t;
  t << "patch,row,illuminant,capture,r_mean,g_mean,b_mean,r_sd,g_sd,b_sd,n_pixels,exposure,radiance_file,radiance_column\n";
  for (auto& p : s.data.patches) {
    char b[256];
    std::snprintf(b, sizeof b, "%s,%s,%s,%s,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.0f,1,radiance.csv,%s_%s\n", p.id.c_str(),
                  p.conditions.at("row").c_str(), p.conditions.at("illuminant").c_str(), p.conditions.at("capture").c_str(), p.rgb[0],
                  p.rgb[1], p.rgb[2], p.sd[0], p.sd[1], p.sd[2], p.n_pixels, p.id.c_str(), p.conditions.at("illuminant").c_str());
    t << b;
  }
  write_file_atomic(dir + "/patches.csv", t.str());
  std::printf("hidden effect %s:", s.effect_id.c_str());
  for (auto& [k, v] : s.truth) std::printf(" %s=%.4f", k.c_str(), v);
  std::printf("\n");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.describe().c_str());
    return 2;
  }
}
