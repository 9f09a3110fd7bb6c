#include "tests/fuzz/diagnose_selection.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"
#include "renderer/diagnose/camera/camera_model.h"
#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/diagnose/diagnose_job.h"
#include "renderer/diagnose/diagnose_model.h"
#include "renderer/diagnose/report/diagnose_report.h"
#include "renderer/diagnose/spectra/forward_model.h"
#include "renderer/diagnose/selection/global_fit.h"
#include "tests/support/synthetic.h"

namespace ofl::fuzz {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The input bytes as a stream of choices; an exhausted stream answers 0: the first option, and
// "no" to every chance, so a short input is a small, cheap case.
class Choices {
 public:
  Choices(const uint8_t* d, size_t n) : d_(d), n_(n) {}
  unsigned byte() { return k_ < n_ ? d_[k_++] : 0u; }
  int pick(int n) { return n <= 1 ? 0 : static_cast<int>(((byte() << 8) | byte()) % static_cast<unsigned>(n)); }
  double unit() { return static_cast<double>((byte() << 8) | byte()) / 65535.0; }
  double uniform(double a, double b) { return a + (b - a) * unit(); }
  bool chance(int percent) { return static_cast<int>(byte() % 100) >= 100 - percent; }
  template <class T>
  const T& one_of(const std::vector<T>& v) { return v[static_cast<size_t>(pick(static_cast<int>(v.size())))]; }

 private:
  const uint8_t* d_;
  size_t n_, k_ = 0;
};

// This process's scratch folder for one case (emptied before each case).
fs::path case_folder() {
  static const fs::path d = fs::temp_directory_path() / ("ofl_fuzz_selection_" + std::to_string(::getpid()));
  std::error_code ec;
  fs::remove_all(d, ec);
  fs::create_directories(d / "spectra");
  return d;
}

void write_text(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::trunc) << s; }

// What the data folder will hold, decided together with the model.
struct Plan {
  std::vector<int> light_nm;      // one per light entry
  int subjects = 2, locations = 1;
  std::vector<std::string> sites;
  double step_nm = 2, first_nm = 380, last_nm = 780;
};

json random_light(Choices& c, int nm, bool with_leak, const fs::path& dir, int k) {
  json e = {{"name", "light " + std::to_string(k)}, {"when", {{"light_nm", nm}}}};
  const std::string L = (asset_root() / "lights/oe_tongue_lip/ExcitationLights").string() + "/";
  const std::vector<std::string> shipped = {"spd-2024-03-07-verif-405nm450SPF-980mA.csv", "spd-2024-03-07-verif-415nm450SPF-910mA.csv",
                                            "spd-2024-03-07-verif-450nm450SPF-870mA.csv"};
  switch (c.pick(3)) {
    case 0: e["spectrum"] = {{"type", "gaussian"}, {"peak_nm", nm + c.uniform(-3, 3)}, {"fwhm_nm", c.uniform(3, 40)}}; break;
    case 1: e["spectrum"] = L + c.one_of(shipped); break;
    default: {
      // A point table written as a CSV: a triangle with a long weak tail (what an LED behind a
      // short-pass looks like to a spectroradiometer).
      fs::path f = dir / ("light" + std::to_string(k) + ".csv");
      double w = c.uniform(4, 20), tail = std::pow(10.0, -c.uniform(2, 6));
      std::string s = "wavelength_nm,radiance\n";
      for (double x = 350; x <= 800; x += 1) {
        double v = std::max(0.0, 1 - std::fabs(x - nm) / w) + (x > nm ? tail : 0.0);
        s += std::to_string(x) + "," + std::to_string(v) + "\n";
      }
      write_text(f, s);
      e["spectrum"] = f.string();
    }
  }
  if (with_leak) {
    if (c.chance(50))
      e["leak"] = {{"type", "gaussian"}, {"peak_nm", c.uniform(470, 540)}, {"fwhm_nm", c.uniform(5, 80)}};
    else
      e["leak"] = L + c.one_of(std::vector<std::string>{"spd-2024-03-17-NoiseCheck-405nm_980mA.csv",
                                                         "spd-2024-03-17-NoiseCheck-450nm_870mA.csv"});
  }
  return e;
}

json random_emission_filter(Choices& c, const fs::path& dir) {
  switch (c.pick(4)) {
    case 0: return nullptr;
    case 1: {
      // A measured hard step: a floor below the edge, a plateau above.
      double edge = c.uniform(455, 500), floor = std::pow(10.0, -c.uniform(1, 7)), top = c.uniform(0.3, 1);
      std::string s = "wavelength_nm,transmittance\n300," + std::to_string(floor) + "\n" + std::to_string(edge - 0.01) + "," +
                      std::to_string(floor) + "\n" + std::to_string(edge) + "," + std::to_string(top) + "\n900," + std::to_string(top) + "\n";
      write_text(dir / "longpass.csv", s);
      return {{"type", "measured"}, {"file", (dir / "longpass.csv").string()}};
    }
    default:
      return {{"type", "longpass"}, {"edge_nm", c.uniform(455, 500)}, {"width_nm", c.uniform(0.5, 15)}, {"od", c.uniform(1, 8)}};
  }
}

json random_candidates(Choices& c) {
  json k = json::object();
  for (const char* name : {"blood_absorption", "wavelength_shift", "bandwidth", "emission_broadening", "stray_light", "longpass_leak",
                           "longpass_edge", "emission_shift", "fluorophore_shape", "second_band", "unknown_band", "instrument_response"})
    k[name] = c.chance(30);
  if (c.chance(50)) {
    json from = json::array();
    for (const char* f : {"protoporphyrin", "chlorophyll_a", "porphyrin_bacterial", "elastin"})
      if (c.chance(40)) from.push_back(f);
    k["extra_fluorophore"] = from.empty() ? json(false) : json{{"from", from}};
  } else {
    k["extra_fluorophore"] = false;
  }
  return k;
}

json random_model(Choices& c, const fs::path& dir, Plan& plan) {
  json m = {{"format", "oralfluor-diagnose-model/1"}, {"kind", "spectra"}, {"file_column", "csv"}};
  const int lights = 1 + c.pick(2);
  const std::vector<int> nms = {385, 405, 415, 450};
  const std::string leak = c.one_of(std::vector<std::string>{"none", "computed", "measured"});
  json entries = json::array();
  for (int k = 0; k < lights; ++k) {
    int nm = c.one_of(nms);
    plan.light_nm.push_back(nm);
    entries.push_back(random_light(c, nm, leak == "measured" || c.chance(20), dir, k));
  }
  m["lights"] = {{"entries", entries}, {"floor_fraction", c.chance(70) ? 1e-3 : c.uniform(0, 0.5)}};
  if (json f = random_emission_filter(c, dir); !f.is_null()) m["emission_filter"] = f;
  if (c.chance(20)) m["excitation_filter"] = {{"type", "shortpass"}, {"edge_nm", c.uniform(430, 470)}, {"width_nm", 5}, {"od", 4}};
  m["leak"] = leak;
  double lo = c.uniform(380, 520);
  m["fit_range_nm"] = {lo, std::min(800.0, lo + c.uniform(c.chance(10) ? 2 : 60, 350))};
  m["grid_step_nm"] = c.one_of(std::vector<double>{2, 3, 5, 2, 1});
  m["instrument_fwhm_nm"] = c.chance(70) ? 0.0 : c.uniform(0, 12);
  json fl = json::array();
  for (const char* f : {"collagen", "NADH", "FAD", "keratin"})
    if (c.chance(55)) fl.push_back(f);
  if (!fl.empty() || c.chance(80)) m["fluorophores"] = fl.empty() ? json::array({"FAD"}) : fl;
  m["candidates"] = random_candidates(c);
  const bool stray = m["candidates"]["stray_light"].get<bool>();
  const std::vector<std::vector<std::string>> groups = {{"subject"}, {"subject", "site"}, {"site"}, {"location"}};
  m["groups"] = c.one_of(groups);
  if (c.chance(80)) m["replicates"] = c.chance(70) ? json{"subject", "site", "light_nm"} : json{"subject"};
  m["report_by"] = c.one_of(std::vector<std::string>{"subject", "site", "", "light_nm"});
  m["selection"] = {{"z", c.uniform(0.5, 5)}, {"max_causes", 1 + c.pick(2)}, {"min_fold_fraction", c.uniform(0, 0.9)}};
  if (c.chance(15)) m["shared_concentrations"] = json{"subject", "site"};
  if (c.chance(10) && (stray || c.chance(10))) m["plausible"] = {{"stray_light", {{"fraction_of_peak", {0, c.uniform(0, 0.5)}}}}};
  plan.sites = c.chance(50) ? std::vector<std::string>{"lip", "tongue"} : std::vector<std::string>{c.chance(50) ? "lip" : "tongue"};
  if (c.chance(6))
    m["layered_tissue"] = {{"sites", {{"tongue", "dorsal_tongue"}}}, {"site_column", c.chance(90) ? "site" : "subject"},
                           {"photons", 100}, {"transport_step_nm", 20}, {"thickness_mm", {0.1, 0.3}},
                           {"blood_fraction", {0.0, 0.02}}, {"saturation", {1.0}}};
  plan.subjects = 1 + c.pick(3);
  plan.locations = 1 + c.pick(2);
  plan.step_nm = c.one_of(std::vector<double>{1, 2, 3, 4.5});
  plan.first_nm = c.uniform(370, 470);
  plan.last_nm = c.uniform(600, 790);
  return m;
}

struct Row {
  std::string file;
  std::map<std::string, std::string> cond;
};

std::vector<Row> index_rows(const Plan& plan) {
  std::vector<Row> rows;
  for (int s = 0; s < plan.subjects; ++s)
    for (auto& site : plan.sites)
      for (size_t l = 0; l < plan.light_nm.size(); ++l)
        for (int loc = 0; loc < plan.locations; ++loc) {
          Row r;
          r.file = "spectra/s" + std::to_string(rows.size()) + ".csv";
          r.cond = {{"subject", "S" + std::to_string(s + 1)}, {"site", site}, {"light_nm", std::to_string(plan.light_nm[l])},
                    {"location", "R0" + std::to_string(loc + 1)}, {"category", "tissue"}};
          rows.push_back(r);
        }
  return rows;
}

// A hidden state of 0-2 random candidates with random parameters within their bounds.
ModelState hidden_state(Choices& c, const SpectraProblem& p) {
  ModelState s = baseline_state(p);
  const int C = static_cast<int>(p.candidates().size());
  for (int n = c.pick(3); n > 0 && C > 0; --n) {
    int k = c.pick(C);
    if (s.has(k) || p.candidates()[k].name == "layered_tissue") continue;
    s = with_cause(p, s, k);
    auto& th = s.causes.back().theta;
    const auto& ps = p.candidates()[k].params;
    for (size_t j = 0; j < th.size(); ++j) {
      double lo = std::isfinite(ps[j].lo) ? ps[j].lo : ps[j].init - 1, hi = std::isfinite(ps[j].hi) ? ps[j].hi : ps[j].init + 1;
      th[j] = c.chance(30) ? ps[j].init : c.uniform(lo, hi);
    }
  }
  return s;
}

// Values of every row's spectrum: the model's columns under the hidden state with random
// amplitudes (fit range), a placeholder level outside it, noise, and sometimes damage. Amplitudes
// and noise come from a generator seeded by two bytes, so that a short input still describes data.
std::vector<std::vector<double>> make_values(Choices& c, const std::vector<double>& nm, const SpectraProblem* p, const ModelState& truth,
                                             const SpectraModel& model) {
  const int n = static_cast<int>(nm.size());
  std::mt19937 rng(c.byte() * 257u + c.byte());
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> normal(0, 1);
  const double noise = c.uniform(0, 0.05);
  const int damaged = c.chance(15) ? c.pick(std::max(1, p ? p->num_items() : 1)) : -1;
  const int damage = c.pick(4);
  std::vector<std::vector<double>> out;
  const int items = p ? p->num_items() : 1;
  for (int i = 0; i < items; ++i) {
    std::vector<double> v(n, 1.0);
    if (p) {
      auto D = p->design(truth, i);
      Eigen::VectorXd x(D.A.cols());
      for (Eigen::Index j = 0; j < x.size(); ++j) {
        const bool fluorophore = std::find(model.fluorophores.begin(), model.fluorophores.end(), D.names[j]) != model.fluorophores.end();
        x[j] = (fluorophore ? 0.05 + u(rng) : 0.1 * u(rng)) / std::max(D.A.col(j).mean(), 1e-300);
      }
      Eigen::VectorXd y = D.A * x;
      double ybar = std::max(std::fabs(y.mean()), 1e-12);
      int k = 0;
      for (int r = 0; r < n; ++r)
        v[r] = nm[r] >= model.fit_min_nm && nm[r] <= model.fit_max_nm && k < y.size() ? y[k++] : 0.01 * ybar;
      for (double& e : v) e += noise * std::sqrt(std::fabs(e) * ybar) * normal(rng);
    }
    if (i == damaged) switch (damage) {
        case 0: std::fill(v.begin(), v.end(), 0.0); break;
        case 1: for (double& e : v) e = -std::fabs(e); break;
        case 2: std::fill(v.begin(), v.end(), 1e-3); break;
        default: for (double& e : v) e *= 1e30; break;
      }
    out.push_back(v);
  }
  return out;
}

// Writes index.csv and the spectra; the values come from the model when it builds.
void write_data(Choices& c, const fs::path& dir, const Plan& plan, const DiagnoseModelFile* model) {
  auto rows = index_rows(plan);
  std::vector<double> nm;
  for (double w = plan.first_nm; w <= plan.last_nm; w += plan.step_nm) nm.push_back(w);
  SpectraSet tmpl;
  tmpl.index_file = (dir / "index.csv").string();
  for (auto& r : rows) {
    MeasuredSpectrum m;
    m.file = (dir / r.file).string();
    m.label = r.file;
    m.conditions = r.cond;
    m.nm = nm;
    m.value.assign(nm.size(), 1.0);
    tmpl.spectra.push_back(m);
  }
  std::unique_ptr<SpectraProblem> p;
  ModelState truth;
  if (model) {
    try {
      p = std::make_unique<SpectraProblem>(tmpl, model->spectra);
      truth = hidden_state(c, *p);
    } catch (const InputError&) {
      p.reset();  // the job below meets the same error through the command's own path
    }
  }
  auto values = make_values(c, nm, p.get(), truth, model ? model->spectra : SpectraModel{});
  std::string index = "csv,subject,site,light_nm,location,category\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    auto& r = rows[i];
    index += r.file + "," + r.cond["subject"] + "," + r.cond["site"] + "," + r.cond["light_nm"] + "," + r.cond["location"] + ",tissue\n";
    const auto& v = values[std::min(i, values.size() - 1)];
    std::string s = "wavelength_nm,radiance\n";
    char b[64];
    for (size_t k = 0; k < nm.size(); ++k) {
      std::snprintf(b, sizeof b, "%.6f,%.9g\n", nm[k], v[k]);
      s += b;
    }
    write_text(dir / r.file, s);
  }
  write_text(dir / "index.csv", index);
}

DiagnoseJob random_job(Choices& c, const fs::path& dir, const Plan& plan) {
  DiagnoseJob job;
  job.input = dir.string();
  job.model = (dir / "model.json").string();
  if (c.chance(20)) job.outdir = (dir / "out").string();
  if (c.chance(10)) job.where.push_back(c.chance(50) ? "site=lip" : "light_nm=" + std::to_string(plan.light_nm[0]));
  if (c.chance(10)) job.groups = {c.chance(50) ? "subject" : "site"};
  if (c.chance(10)) job.z = c.uniform(0, 6);
  if (c.chance(10)) job.max_causes = c.pick(4);
  if (c.chance(20)) {
    job.fit_on = c.one_of(std::vector<std::string>{"subject=S1", "subject=S1,S2", "site=lip", "subject", "subject=S9"});
    if (c.chance(50)) job.predict = c.one_of(std::vector<std::string>{"subject=S2", "subject=S1", "subject=S3", "site=tongue"});
  }
  if (c.chance(8)) job.shared_concentrations = {"subject", "site"};
  return job;
}

void run_spectra_case(Choices& c) {
  const fs::path dir = case_folder();
  Plan plan;
  json model = random_model(c, dir, plan);
  write_text(dir / "model.json", model.dump(1));
  std::optional<DiagnoseModelFile> m;
  try {
    m = load_diagnose_model(dir / "model.json");
  } catch (const InputError&) {
  }
  write_data(c, dir, plan, m ? &*m : nullptr);
  DiagnoseOutcome out = run_diagnose_job(random_job(c, dir, plan));
  if (std::getenv("OFL_FUZZ_VERBOSE"))
    std::fprintf(stderr, "fuzz_diagnose_selection: %d spectra, %zu causes: %s\n", out.report["items"].get<int>(),
                 out.report["causes"].size(), out.report["verdict"].get<std::string>().c_str());
}

// A synthetic camera patch set (random hidden camera cause), thinned and damaged, selected and
// reported through the camera problem.
void run_camera_case(Choices& c) {
  SyntheticCameraOptions o;
  o.seed = 1 + c.byte();
  o.effect = c.one_of(std::vector<std::string>{"", "channel_gain", "crosstalk", "offset", "nonlinearity", "qe_shift", "nir_leak"});
  o.captures = 1 + c.pick(2);
  SyntheticCamera s = make_synthetic_camera(o);
  auto& patches = s.data.patches;
  const int keep = c.pick(25);
  for (int i = static_cast<int>(patches.size()) - 1; i >= 0; --i)
    if (static_cast<int>(patches.size()) > keep && c.chance(85)) patches.erase(patches.begin() + i);
  for (auto& pt : patches)
    if (c.chance(5)) pt.rgb[c.pick(3)] = c.chance(50) ? 0.0 : -1e6;
  if (c.chance(20)) s.model.grid_step_nm = c.uniform(0.5, 40);
  CameraProblem p(s.data, s.model);
  SelectionOptions sel;
  sel.group_columns = {c.chance(70) ? "row" : "illuminant"};
  sel.replicate_columns = {"patch", "illuminant"};
  sel.report_by = c.chance(50) ? "illuminant" : "";
  sel.max_causes = 1 + c.pick(2);
  sel.z = c.uniform(0.5, 5);
  Diagnosis d = diagnose(p, sel);
  ReportContext ctx;
  ctx.input = "fuzz";
  (void)diagnosis_json(p, d, ctx);
  (void)diagnosis_text(p, d, ctx);
}

}  // namespace

void run_diagnose_selection(const uint8_t* data, size_t size) {
  Choices c(data, size);
  if (c.chance(20))
    run_camera_case(c);
  else
    run_spectra_case(c);
}

}  // namespace ofl::fuzz
