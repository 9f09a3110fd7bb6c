#include "renderer/validation/references/mcml.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "renderer/core/errors/error.h"
#include "renderer/render/stack/stack_walk.h"

namespace ofl {

namespace {

// Whitespace-separated tokens of an MCML file with their line numbers, comments (#...) removed.
struct Tokens {
  std::string file;
  std::vector<std::pair<std::string, int>> t;
  size_t i = 0;
  explicit Tokens(const std::filesystem::path& p) : file(p.string()) {
    std::ifstream in(p);
    if (!in) throw InputError(file, "", "cannot open file");
    std::string line;
    int no = 0;
    while (std::getline(in, line)) {
      ++no;
      if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
      std::istringstream ss(line);
      std::string w;
      while (ss >> w) t.emplace_back(w, no);
    }
  }
  [[noreturn]] void fail(const std::string& what) const {
    int line = i < t.size() ? t[i].second : (t.empty() ? 0 : t.back().second);
    throw InputError(file, "line " + std::to_string(line), what);
  }
  const std::string& word(const char* what) {
    if (i >= t.size()) fail(std::string("file ends where ") + what + " was expected");
    return t[i++].first;
  }
  double number(const char* what, double lo, double hi) {
    const std::string& w = word(what);
    char* end = nullptr;
    double v = std::strtod(w.c_str(), &end);
    if (end == w.c_str() || *end != '\0' || !std::isfinite(v)) {
      --i;
      fail(std::string(what) + ": \"" + w + "\" is not a number");
    }
    if (v < lo || v > hi) {
      --i;
      std::ostringstream m;
      m << what << " = " << v << " is outside [" << lo << ", " << hi << "]";
      fail(m.str());
    }
    return v;
  }
  long long integer(const char* what, long long lo, long long hi) {
    double v = number(what, double(lo), double(hi));
    if (v != std::floor(v)) {
      --i;
      fail(std::string(what) + " must be a whole number");
    }
    return (long long)v;
  }
};

}  // namespace

std::vector<McmlInput> read_mci(const std::filesystem::path& file) {
  Tokens tk(file);
  tk.number("file version", 0, 100);
  int runs = int(tk.integer("number of runs", 1, 1000));
  std::vector<McmlInput> out;
  for (int r = 0; r < runs; ++r) {
    McmlInput in;
    in.name = std::filesystem::path(tk.word("output file name")).stem().string();
    tk.word("output file type (A or B)");
    in.photons = tk.integer("number of photons", 1, (long long)1e12);
    in.dz_cm = tk.number("dz", 1e-9, 1e6);
    in.dr_cm = tk.number("dr", 1e-9, 1e6);
    in.nz = int(tk.integer("nz", 1, 100000));
    in.nr = int(tk.integer("nr", 1, 100000));
    in.na = int(tk.integer("na", 1, 100000));
    int nl = int(tk.integer("number of layers", 1, kMaxStackLayers));
    in.n_above = tk.number("n above", 1.0, 3.0);
    for (int l = 0; l < nl; ++l) {
      McmlLayer L;
      L.n = tk.number("layer n", 1.0, 3.0);
      L.mua_per_cm = tk.number("layer mua", 0.0, 1e6);
      L.mus_per_cm = tk.number("layer mus", 0.0, 1e7);
      L.g = tk.number("layer g", -0.99, 0.99);
      L.d_cm = tk.number("layer thickness", 0.0, 1e4);
      in.layers.push_back(L);
    }
    in.n_below = tk.number("n below", 1.0, 3.0);
    out.push_back(in);
  }
  return out;
}

McmlOutput read_mco(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot open file");
  McmlOutput o;
  std::string line, section;
  std::vector<double>* list = nullptr;
  std::vector<double> rat;
  int no = 0;
  auto value = [&](const std::string& s) {
    std::istringstream ss(s);
    double v;
    if (!(ss >> v) || !std::isfinite(v)) throw InputError(file.string(), "line " + std::to_string(no), "expected a number in section " + section);
    return v;
  };
  bool in_parm = false;
  std::vector<std::string> parm;
  while (std::getline(in, line)) {
    ++no;
    std::string body = line.substr(0, line.find('#'));
    std::istringstream ss(body);
    std::string first;
    if (!(ss >> first)) { list = nullptr; continue; }  // blank line ends a list
    // A section starts with its name (the output file name inside InParm starts with a letter too).
    static const std::set<std::string> kSections = {"InParm", "RAT", "A_l", "A_z", "Rd_r", "Rd_a",
                                                    "Tt_r",   "Tt_a", "A_rz", "Rd_ra", "Tt_ra"};
    if (kSections.count(first)) {
      section = first;
      in_parm = section == "InParm";
      list = section == "RAT" ? &rat : section == "A_l" ? &o.a_layer : section == "A_z" ? &o.a_z : section == "Rd_r" ? &o.rd_r : nullptr;
      if (in_parm) continue;
      if (!in_parm && !list) continue;
      continue;
    }
    if (in_parm) {
      std::string w = first;
      do parm.push_back(w); while (ss >> w);
      continue;
    }
    if (list) list->push_back(value(first));
  }
  if (rat.size() < 4) throw InputError(file.string(), "RAT", "missing the reflectance/absorption/transmission section");
  o.rsp = rat[0];
  o.rd = rat[1];
  o.a = rat[2];
  o.tt = rat[3];
  // InParm: output name, type, photons, dz, dr, ...
  if (parm.size() >= 5) {
    o.photons = std::atoll(parm[2].c_str());
    o.dz_cm = std::atof(parm[3].c_str());
    o.dr_cm = std::atof(parm[4].c_str());
  }
  if (o.a_layer.empty()) throw InputError(file.string(), "A_l", "missing the absorption-per-layer section");
  return o;
}

LayerStack mcml_stack(const McmlInput& in) {
  LayerStack st;
  st.enabled = true;
  st.ambient_ior = in.n_above;
  st.bottom = StackBottom::kOpen;
  st.below_ior = in.n_below;
  for (size_t i = 0; i < in.layers.size(); ++i) {
    const McmlLayer& L = in.layers[i];
    TissueLayer t;
    t.name = "layer" + std::to_string(i + 1);
    t.thickness_mm = L.d_cm * 10.0;
    t.ior = L.n;
    t.g = L.g;
    t.mua = {L.mua_per_cm / 10.0};
    t.mus = {L.mus_per_cm / 10.0};
    st.layers.push_back(t);
  }
  return st;
}

namespace {

// Per-photon tallies (MCML's quantities plus the lateral position of diffuse exits).
struct PhotonTally {
  double x = 0, y = 0;
  std::vector<double> absorbed;         // per layer, this photon
  std::vector<double> absorbed_binned;  // per layer, MCML's depth-bin assignment
  std::vector<int> bin_layer;           // layer of each depth bin (by its centre)
  double dz_mm = 0;
  void moved(const glm::dvec3& d, double s) {
    x += d.x * s;
    y += d.y * s;
  }
  void collision(const WalkState& s, const LaneCoefficients& c, const WalkLanes& lanes) {
    double a = double(lanes.w[0]) * c.mua[0];
    absorbed[s.layer] += a;
    int iz = std::min(int(bin_layer.size()) - 1, int(s.depth / dz_mm));
    absorbed_binned[bin_layer[iz]] += a;
  }
  void base_vertex(const WalkState&, const WalkLanes&) {}
};

struct Accumulator {
  double rsp = 0, rd = 0, rd2 = 0, tt = 0, tt2 = 0;
  std::vector<double> a, a2, ab, ab2;
  std::vector<std::pair<double, double>> exits;  // (radius mm, weight) of diffuse exits
  explicit Accumulator(size_t layers = 0) : a(layers, 0.0), a2(layers, 0.0), ab(layers, 0.0), ab2(layers, 0.0) {}
  void add(const Accumulator& o) {
    rsp += o.rsp;
    rd += o.rd;
    rd2 += o.rd2;
    tt += o.tt;
    tt2 += o.tt2;
    for (size_t l = 0; l < a.size(); ++l) {
      a[l] += o.a[l];
      a2[l] += o.a2[l];
      ab[l] += o.ab[l];
      ab2[l] += o.ab2[l];
    }
    exits.insert(exits.end(), o.exits.begin(), o.exits.end());
  }
};

// MCML's depth bins of dz_mm and the layer each belongs to (the one holding the bin's centre).
std::vector<int> mcml_bin_layers(const LayerStack& stack, int nz, double dz_mm) {
  const size_t nl = stack.layers.size();
  std::vector<int> bin_layer(std::max(nz, 1));
  for (size_t iz = 0; iz < bin_layer.size(); ++iz) {
    double zc = (iz + 0.5) * dz_mm, bottom = 0;
    int l = 0;
    for (; l + 1 < int(nl); ++l) {
      bottom += stack.layers[l].thickness_mm;
      if (zc < bottom) break;
    }
    bin_layer[iz] = l;
  }
  return bin_layer;
}

// Photons [first, end) of a pencil beam at normal incidence, into A: specular and diffuse
// reflectance, transmittance, absorption per layer (whole and in MCML's bins), diffuse exit radii.
void trace_photons(const StackWalker& walker, double r_spec, long long first, long long end, PhotonTally& tally, Rng& rng,
                   Accumulator& A) {
  const size_t nl = A.a.size();
  for (long long i = first; i < end; ++i) {
    A.rsp += r_spec;
    WalkLanes lanes;
    lanes.count = 1;
    lanes.wl[0] = 0;
    lanes.w[0] = float(1.0 - r_spec);
    WalkState s;
    s.d = glm::dvec3(0, 0, -1);
    tally.x = tally.y = 0;
    std::fill(tally.absorbed.begin(), tally.absorbed.end(), 0.0);
    std::fill(tally.absorbed_binned.begin(), tally.absorbed_binned.end(), 0.0);
    WalkResult r = walker.walk(s, lanes, StackPointFactors(), rng, tally);
    double w = lanes.w[0];
    if (r.end == WalkEnd::kExitTop) {
      if (!r.turbid) {
        A.rsp += w;
      } else {
        A.rd += w;
        A.rd2 += w * w;
        A.exits.emplace_back(std::hypot(tally.x, tally.y), w);
      }
    } else if (r.end == WalkEnd::kExitBottom) {
      A.tt += w;
      A.tt2 += w * w;
    }
    for (size_t l = 0; l < nl; ++l) {
      A.a[l] += tally.absorbed[l];
      A.a2[l] += tally.absorbed[l] * tally.absorbed[l];
      A.ab[l] += tally.absorbed_binned[l];
      A.ab2[l] += tally.absorbed_binned[l] * tally.absorbed_binned[l];
    }
  }
}

// The totals of T over N photons, with standard errors, and the radius holding 90 % of Rd.
SlabResult slab_result(Accumulator& T, long long photons) {
  const size_t nl = T.a.size();
  const double N = double(photons);
  auto se = [N](double s, double s2) { return std::sqrt(std::max(0.0, s2 / N - (s / N) * (s / N)) / N); };
  SlabResult r;
  r.photons = photons;
  r.rsp = T.rsp / N;
  r.rd = T.rd / N;
  r.rd_se = se(T.rd, T.rd2);
  r.tt = T.tt / N;
  r.tt_se = se(T.tt, T.tt2);
  for (size_t l = 0; l < nl; ++l) {
    r.a_layer.push_back(T.a[l] / N);
    r.a_layer_se.push_back(se(T.a[l], T.a2[l]));
    r.a_layer_binned.push_back(T.ab[l] / N);
    r.a_layer_binned_se.push_back(se(T.ab[l], T.ab2[l]));
    r.a += T.a[l] / N;
  }
  std::sort(T.exits.begin(), T.exits.end());
  double cum = 0;
  for (auto& [rad, w] : T.exits) {
    cum += w;
    if (cum >= 0.9 * T.rd) { r.r90_mm = rad; break; }
  }
  return r;
}

}  // namespace

SlabResult simulate_slab(const McmlInput& in, long long photons, uint64_t seed) {
  auto t0 = std::chrono::steady_clock::now();
  LayerStack stack = mcml_stack(in);
  const size_t nl = stack.layers.size();
  StackTables st = build_stack_tables(stack, {}, {}, false);
  MaterialTables mt;  // no base
  StackWalker walker(st, mt, 1, WalkMode::kImportance);
  const double r_spec = fresnel_dielectric(1.0, stack.layers[0].ior / stack.ambient_ior);
  const double dz_mm = in.dz_cm > 0 ? in.dz_cm * 10.0 : 0.02;
  const std::vector<int> bin_layer = mcml_bin_layers(stack, in.nz, dz_mm);

  const long long block = 4096;
  const long long blocks = (photons + block - 1) / block;
  std::vector<Accumulator> acc(blocks, Accumulator(nl));
  tbb::parallel_for((long long)0, blocks, [&](long long b) {
    Rng rng(seed, Rng::stream_for(0x4D434D4CULL, uint64_t(b)));
    PhotonTally tally;
    tally.absorbed.assign(nl, 0.0);
    tally.absorbed_binned.assign(nl, 0.0);
    tally.bin_layer = bin_layer;
    tally.dz_mm = dz_mm;
    trace_photons(walker, r_spec, b * block, std::min(photons, (b + 1) * block), tally, rng, acc[b]);
  });
  Accumulator T(nl);
  for (auto& A : acc) T.add(A);
  SlabResult r = slab_result(T, photons);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

double mcml_radius_holding(const McmlOutput& out, double fraction) {
  if (out.rd_r.empty() || !(out.dr_cm > 0) || !(out.rd > 0)) return -1;
  double cum = 0;
  const size_t n = out.rd_r.size();
  for (size_t i = 0; i + 1 < n; ++i) {  // the last bin is MCML's overflow
    double r0 = i * out.dr_cm, r1 = (i + 1) * out.dr_cm;
    double add = out.rd_r[i] * kPi * (r1 * r1 - r0 * r0);
    if (cum + add >= fraction * out.rd) {
      double f = (fraction * out.rd - cum) / add;
      return 10.0 * (r0 + f * (r1 - r0));
    }
    cum += add;
  }
  return -1;
}

std::vector<BenchCheck> compare_with_mcml(const SlabResult& o, const McmlOutput& m) {
  std::vector<BenchCheck> c;
  const double nm = m.photons > 0 ? double(m.photons) : 1e6;
  auto mcml_se = [nm](double x) { return std::sqrt(std::max(x * (1 - x), 0.0) / nm); };
  auto tol = [&](double rel, double ours_se, double ref) { return mc_tolerance(rel, ref, std::hypot(ours_se, mcml_se(ref))); };
  c.push_back({"specular reflectance Rsp", o.rsp, m.rsp, 1e-4});
  c.push_back({"diffuse reflectance Rd", o.rd, m.rd, tol(0.01, o.rd_se, m.rd)});
  if (m.tt > 0 || o.tt > 0) c.push_back({"transmittance Tt", o.tt, m.tt, tol(0.01, o.tt_se, m.tt)});
  for (size_t l = 0; l < m.a_layer.size() && l < o.a_layer_binned.size(); ++l)
    c.push_back({"absorbed in layer " + std::to_string(l + 1) + " (MCML's depth bins)", o.a_layer_binned[l], m.a_layer[l],
                 std::max(tol(0.02, o.a_layer_binned_se[l], m.a_layer[l]), 2e-4)});
  return c;
}

CheckCaseResult mcml_case(const McmlInput& in, const McmlOutput* ref, long long photons, uint64_t seed) {
  SlabResult o = simulate_slab(in, photons, seed);
  CheckCaseResult r;
  r.name = "mcml_" + in.name;
  r.samples = photons;
  r.seconds = o.seconds;
  r.extra["oralfluor"] = {{"Rsp", o.rsp}, {"Rd", o.rd}, {"Rd_se", o.rd_se}, {"Tt", o.tt}, {"Tt_se", o.tt_se}, {"A", o.a},
                          {"A_layer", o.a_layer}, {"A_layer_se", o.a_layer_se}, {"A_layer_mcml_bins", o.a_layer_binned},
                          {"r90_mm", o.r90_mm}};
  if (ref) {
    r.extra["mcml"] = {{"Rsp", ref->rsp}, {"Rd", ref->rd}, {"Tt", ref->tt}, {"A", ref->a}, {"A_layer", ref->a_layer},
                       {"photons", ref->photons}};
    double r90 = mcml_radius_holding(*ref, 0.9);
    if (r90 > 0) r.extra["mcml"]["r90_mm"] = r90;
    r.checks = compare_with_mcml(o, *ref);
  }
  return r;
}

std::filesystem::path mcml_case_dir() { return std::filesystem::path(OFL_SOURCE_DIR) / "benchmarks" / "mcml"; }

std::vector<std::string> mcml_case_names() {
  std::vector<std::string> names;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(mcml_case_dir(), ec))
    if (e.path().extension() == ".mci") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace ofl
