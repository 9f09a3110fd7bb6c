// Validation of the layered-tissue random walk against MCML (Wang, Jacques & Zheng, Comput Methods
// Programs Biomed 47:131, 1995), the reference code of tissue optics. Reads MCML's input (.mci)
// and output (.mco) files, runs the same slab through oralfluor's walk (renderer/render/
// stack/stack_walk.h, importance mode: photons from a normally incident pencil beam, one wavelength)
// and compares specular and diffuse reflectance, transmittance and the fraction absorbed in each
// layer. MCML's units are kept at this boundary (cm, 1/cm); the walk works in mm.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "materials/description/layered.h"
#include "renderer/validation/harness/bench_check.h"

namespace ofl {

struct McmlLayer {
  double n = 1, mua_per_cm = 0, mus_per_cm = 0, g = 0, d_cm = 0;
};

// One run of an .mci file.
struct McmlInput {
  std::string name;       // case name (the output file's stem)
  long long photons = 0;
  double dz_cm = 0, dr_cm = 0;
  int nz = 0, nr = 0, na = 0;
  double n_above = 1, n_below = 1;
  std::vector<McmlLayer> layers;
};

// The headline numbers of an .mco file (MCML's "RAT", "A_l", "A_z", "Rd_r" sections).
struct McmlOutput {
  long long photons = 0;
  double rsp = 0, rd = 0, a = 0, tt = 0;
  std::vector<double> a_layer;
  double dz_cm = 0, dr_cm = 0;
  std::vector<double> a_z;   // 1/cm
  std::vector<double> rd_r;  // 1/cm^2 (the last bin collects everything beyond)
};

// Errors name the file and line (InputError).
std::vector<McmlInput> read_mci(const std::filesystem::path& file);
McmlOutput read_mco(const std::filesystem::path& file);

// The slab as an oralfluor layer stack on a one-bin grid (clear space of n_below under it).
LayerStack mcml_stack(const McmlInput& in);

// oralfluor's answer for the slab: means and standard errors over photons.
struct SlabResult {
  long long photons = 0;
  double rsp = 0, rd = 0, rd_se = 0, tt = 0, tt_se = 0, a = 0;
  std::vector<double> a_layer, a_layer_se;  // absorbed in each layer, exactly
  // Absorbed per layer as MCML reports it: MCML tallies absorption in depth bins of dz (the last
  // bin collecting everything deeper) and gives each bin to the layer that holds its centre, so a
  // layer boundary inside a bin moves that bin's absorption to one side. Compared with MCML's A_l.
  std::vector<double> a_layer_binned, a_layer_binned_se;
  double r90_mm = 0;   // radius holding 90 % of the diffuse reflectance (lateral spread the position-free walk ignores)
  double seconds = 0;
};
SlabResult simulate_slab(const McmlInput& in, long long photons, uint64_t seed);

// Radius (mm) within which `fraction` of the diffuse reflectance leaves, from MCML's Rd(r) table;
// negative when it lies beyond the table (MCML's last bin collects everything further out).
double mcml_radius_holding(const McmlOutput& out, double fraction);

// The comparison the tests and `oralfluor bench mcml` report, with the tolerances: Rd and
// Tt within 1 % relative or 3 combined standard errors (whichever is larger), each layer's absorbed
// fraction within 2 % relative or 3 standard errors, the specular reflectance within 1e-4.
std::vector<BenchCheck> compare_with_mcml(const SlabResult& ours, const McmlOutput& ref);
// A bench result for a slab: the checks when MCML's output is given, the numbers in `extra`.
CheckCaseResult mcml_case(const McmlInput& in, const McmlOutput* ref, long long photons, uint64_t seed);

// Lateral transport (renderer/validation/references/mcml_radial.cpp): the slab's lateral profiles filled as the
// renderer's spatial transport fills them (renderer/render/spatial/stack_profiles.h), at normal
// incidence, in 8 independent batches; the diffuse reflectance within each of `radii_mm` with its
// standard error, and the radii holding 50 % and 90 % of all of it.
struct RadialSlabResult {
  long long walks = 0;
  double seconds = 0;
  std::vector<double> radii_mm, cumulative, cumulative_se;
  double rd = 0, rd_se = 0, r50_mm = 0, r50_se = 0, r90_mm = 0, r90_se = 0;
};
RadialSlabResult simulate_slab_radial(const McmlInput& in, long long photons, uint64_t seed, const std::vector<double>& radii_mm);
// Against MCML's Rd_r: the reflectance within r at every ring edge within 1 % of Rd (or 3 combined
// standard errors; the worst edge is reported), r50 and r90 within 2 % (or 3 standard errors), Rd
// within 1 %.
std::vector<BenchCheck> compare_radial_with_mcml(const RadialSlabResult& ours, const McmlOutput& ref);
CheckCaseResult mcml_radial_case(const McmlInput& in, const McmlOutput& ref, long long photons, uint64_t seed);
std::filesystem::path mcml_radial_case_dir();

// The MCML cases shipped with the project (benchmarks/mcml/<case>.mci + .mco).
std::filesystem::path mcml_case_dir();
std::vector<std::string> mcml_case_names();

}  // namespace ofl
