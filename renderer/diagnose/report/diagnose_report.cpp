#include "renderer/diagnose/report/diagnose_report.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/plot/charts.h"
#include "renderer/plot/palette.h"

namespace ofl {

namespace {

std::string f3(double v) {
  char b[48];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

nlohmann::json gains_json(const std::vector<GroupGain>& g) {
  nlohmann::json a = nlohmann::json::array();
  for (auto& x : g)
    a.push_back({{"value", x.value}, {"items", x.items}, {"rmse_before_heldout", x.rmse_before}, {"rmse_after_heldout", x.rmse_after},
                 {"variance_explained_before_heldout", x.ve_before}, {"variance_explained_after_heldout", x.ve_after}});
  return a;
}

nlohmann::json trial_json(const DiagnoseProblem& p, const CandidateTrial& t, int step) {
  return {{"step", step},
          {"id", p.candidates()[t.candidate].id},
          {"rmse_before_heldout", t.rmse_before},
          {"rmse_after_heldout", t.rmse_after},
          {"mean_mse_gain", t.mean_gain},
          {"optimism", t.optimism},
          {"threshold", t.threshold},
          {"sd_noise", t.sd_noise},
          {"se_items", t.se_items},
          {"folds_improved", t.folds_improved},
          {"folds", t.folds},
          {"accepted", t.accepted},
          {"carried_by", t.carried_by},
          {"carriers", t.carriers},
          {"at_bound", t.at_bound},
          {"implausible", t.implausible},
          {"verdict", t.verdict}};
}

std::string slug(std::string s) {
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

void write_text(const std::filesystem::path& f, const std::string& s) {
  write_file_atomic(f, s);
}

// Groups of items by the report_by column (or one group "all").
std::vector<std::pair<std::string, std::vector<int>>> report_groups(const DiagnoseProblem& p, const Diagnosis& d) {
  std::vector<std::pair<std::string, std::vector<int>>> g;
  std::map<std::string, size_t> at;
  for (int i = 0; i < p.num_items(); ++i) {
    std::string v = d.options.report_by.empty() ? "all" : p.condition(i, d.options.report_by);
    if (!at.count(v)) { at[v] = g.size(); g.push_back({v, {}}); }
    g[at[v]].second.push_back(i);
  }
  return g;
}

std::string model_name(const DiagnoseProblem& p, const Diagnosis& d, size_t upto) {
  std::string s = "baseline";
  for (size_t k = 0; k < upto && k < d.causes.size(); ++k) s += " + " + p.candidates()[d.causes[k].candidate].id;
  return s;
}

// Depth against a surface filter (docs/diagnose.md, "Layered tissue"): the held-out RMSE of the
// baseline and of each of blood_absorption and layered_tissue alone on it (step 1), per site and
// excitation. Empty when step 1 did not try both.
struct DepthRow {
  std::string site, light;
  int items = 0;
  double baseline = 0, blood = 0, layered = 0;
};
std::vector<DepthRow> depth_comparison(const DiagnoseProblem& p, const Diagnosis& d) {
  if (d.steps.empty()) return {};
  const CandidateTrial *blood = nullptr, *layered = nullptr;
  for (auto& t : d.steps[0]) {
    if (p.candidates()[t.candidate].id == "blood_absorption") blood = &t;
    if (p.candidates()[t.candidate].id == "layered_tissue") layered = &t;
  }
  if (!blood || !layered || blood->cv.heldout.empty() || layered->cv.heldout.empty()) return {};
  std::map<std::pair<std::string, std::string>, std::vector<int>> cells;
  for (int i = 0; i < p.num_items(); ++i) cells[{p.condition(i, "site"), p.condition(i, "light_nm")}].push_back(i);
  std::vector<DepthRow> rows;
  for (auto& [key, items] : cells) {
    GroupGain b = group_gain(p, d.baseline_cv, blood->cv, items, key.first);
    GroupGain l = group_gain(p, d.baseline_cv, layered->cv, items, key.first);
    rows.push_back({key.first, key.second, int(items.size()), b.rmse_before, b.rmse_after, l.rmse_after});
  }
  return rows;
}

// "0.359 -> 0.119" for a cause also tried alone on the baseline; a cause that needs another in the
// model first (requires_id) was not.
std::string solo_text(const DiagnoseProblem& p, const CauseResult& c) {
  if (c.solo.candidate >= 0) return f3(c.solo.rmse_before) + " -> " + f3(c.solo.rmse_after);
  return "not tried (needs " + p.candidates()[c.candidate].requires_id + " in the model first)";
}

}  // namespace

namespace {

// One accepted cause: what it is, its parameters with uncertainties and units, and its held-out gains.
nlohmann::json cause_json(const DiagnoseProblem& p, const Diagnosis& d, const CauseResult& c) {
  const CandidateSpec& spec = p.candidates()[c.candidate];
  nlohmann::json par = nlohmann::json::object(), unc = nlohmann::json::object(), units = nlohmann::json::object();
  nlohmann::json curv = nlohmann::json::object(), jack = nlohmann::json::object();
  for (size_t k = 0; k < spec.params.size(); ++k) {
    par[spec.params[k].name] = c.theta[k];
    unc[spec.params[k].name] = c.uncertainty[k];
    units[spec.params[k].name] = spec.params[k].unit;
    curv[spec.params[k].name] = c.se_curvature[k];
    jack[spec.params[k].name] = c.se_jackknife[k];
  }
  for (auto& dp : c.derived) {
    par[dp.name] = dp.value;
    unc[dp.name] = dp.uncertainty;
    units[dp.name] = dp.unit;
  }
  if (spec.name == "extra_fluorophore") par["fluorophore"] = spec.id.substr(spec.id.find(':') + 1);
  nlohmann::json cj = {{"name", spec.name},
                       {"id", spec.id},
                       {"title", spec.title},
                       {"instrument", spec.instrument},
                       {"description", c.words},
                       {"step", c.step},
                       {"parameters", par},
                       {"uncertainty", unc},
                       {"units", units},
                       {"uncertainty_curvature", curv},
                       {"uncertainty_group_jackknife", jack},
                       {"rmse_before_heldout", c.trial.rmse_before},
                       {"rmse_after_heldout", c.trial.rmse_after},
                       {"mean_mse_gain", c.trial.mean_gain},
                       {"threshold", c.trial.threshold},
                       {"folds_improved", c.trial.folds_improved},
                       {"folds", c.trial.folds},
                       {"solo_rmse_after_heldout", c.solo.candidate >= 0 ? nlohmann::json(c.solo.rmse_after) : nlohmann::json(nullptr)},
                       {"carried_by", c.trial.carried_by},
                       {"carriers", c.trial.carriers},
                       {"at_bound", c.at_bound}};
  if (!d.options.report_by.empty()) {
    cj["by_" + d.options.report_by] = gains_json(c.by_report);
    if (c.solo.candidate >= 0) cj["solo_by_" + d.options.report_by] = gains_json(c.solo_by_report);
  }
  return cj;
}

// The causes set aside (a better fit held out that the selection rules did not accept).
nlohmann::json set_aside_json(const DiagnoseProblem& p, const Diagnosis& d) {
  nlohmann::json aside = nlohmann::json::array();
  for (auto& a : d.set_aside)
    aside.push_back({{"step", a.step}, {"id", p.candidates()[a.candidate].id}, {"rmse_before_heldout", a.rmse_before},
                     {"rmse_after_heldout", a.rmse_after}, {"reason", a.reason}, {"description", a.words}, {"accepted_instead", a.instead}});
  return aside;
}

// One instrument, checked: each instrument cause's parameters fitted on each value of check_by.
nlohmann::json instrument_check_json(const Diagnosis& d) {
  nlohmann::json checks = nlohmann::json::array();
  for (auto& c : d.instrument_check) {
    nlohmann::json by = nlohmann::json::object();
    for (auto& [v, x] : c.by_value) by[v] = x;
    checks.push_back({{"cause", c.cause_id}, {"parameter", c.param}, {"joint", c.joint}, {"uncertainty", c.uncertainty},
                      {"by_" + d.options.check_by, by}, {"disagree", c.disagree}});
  }
  return checks;
}

// Mean share of each baseline column in the final full-data fit (spectra: fluorophores, leak).
std::map<std::string, double> mean_fractions(const DiagnoseProblem& p, const Diagnosis& d) {
  std::vector<int> all(p.num_items());
  for (int i = 0; i < p.num_items(); ++i) all[i] = i;
  auto fits = p.evaluate(d.final_fit.state, all);
  std::map<std::string, double> share;
  for (auto& f : fits)
    for (auto& [k, v] : f.locals)
      if (k.rfind("fraction:", 0) == 0) share[k.substr(9)] += v / fits.size();
  return share;
}

}  // namespace

nlohmann::json diagnosis_json(const DiagnoseProblem& p, const Diagnosis& d, const ReportContext& ctx) {
  nlohmann::json j;
  j["tool"] = "oralfluor diagnose";
  j["job"] = ctx.job;
  j["kind"] = p.kind();
  j["input"] = ctx.input;
  j["model_file"] = ctx.model_file;
  j["model_options"] = ctx.model_options;
  j["items"] = p.num_items();
  j["notes"] = ctx.notes;
  j["groups"] = {{"columns", d.options.group_columns}, {"folds", d.folds.names}};
  j["report_by"] = d.options.report_by;
  j["rmse_units"] = p.rmse_units();
  j["noise_floor"] = {{"rmse", d.floor.rmse},
                      {"source", d.floor.source},
                      {"replicate_columns", d.options.replicate_columns},
                      {"lag1_autocorrelation", d.floor.lag1},
                      {"independent_fraction", d.floor.n_eff_ratio}};
  j["selection"] = {{"z", d.options.z},
                    {"max_causes", d.options.max_causes},
                    {"min_fold_fraction", d.options.min_fold_fraction},
                    {"min_effect_to_noise", d.options.min_effect_to_noise}};
  j["rmse_baseline_heldout"] = d.rmse_baseline_heldout;
  j["rmse_extended_heldout"] = d.rmse_extended_heldout;
  j["variance_explained_baseline_heldout"] = d.ve_baseline_heldout;
  j["variance_explained_extended_heldout"] = d.ve_extended_heldout;
  j["verdict"] = d.verdict;
  j["baseline_lack_of_fit"] = {{"rmse_over_noise_floor", d.baseline_lack_of_fit},
                               {"common_shape_share", d.common_shape_share},
                               {"instrument_mismatch", d.instrument_mismatch},
                               {"common_shape_nm", d.common_shape_nm},
                               {"common_shape", d.common_shape}};
  j["significant"] = !d.causes.empty();
  nlohmann::json causes = nlohmann::json::array();
  for (auto& c : d.causes) causes.push_back(cause_json(p, d, c));
  j["causes"] = causes;
  j["set_aside"] = set_aside_json(p, d);
  j["instrument_check"] = instrument_check_json(d);
  nlohmann::json tried = nlohmann::json::array();
  for (size_t s = 0; s < d.steps.size(); ++s)
    for (auto& t : d.steps[s]) tried.push_back(trial_json(p, t, static_cast<int>(s + 1)));
  j["candidates_tried"] = tried;
  if (!d.options.report_by.empty()) j["by_" + d.options.report_by] = gains_json(d.by_report);
  j["by_fold"] = gains_json(d.by_fold);
  if (auto rows = depth_comparison(p, d); !rows.empty()) {
    nlohmann::json t = nlohmann::json::array();
    for (auto& r : rows)
      t.push_back({{"site", r.site}, {"light_nm", r.light}, {"items", r.items}, {"baseline", r.baseline},
                   {"blood_absorption", r.blood}, {"layered_tissue", r.layered}});
    j["layered_vs_blood_heldout_rmse"] = t;
  }
  if (auto share = mean_fractions(p, d); !share.empty()) j["mean_fractions_extended_fit"] = share;
  return j;
}

std::string diagnosis_text(const DiagnoseProblem& p, const Diagnosis& d, const ReportContext& ctx) {
  std::ostringstream o;
  o << "oralfluor diagnose: " << p.num_items() << " " << (p.kind() == "spectra" ? "spectra" : "camera patches") << " from "
    << ctx.input << "\n";
  for (auto& n : ctx.notes) o << "  note: " << n << "\n";
  o << "cross-validation: leave one group out, " << d.folds.count() << " groups by";
  for (auto& c : d.options.group_columns) o << " " << c;
  o << "\nRMSE units: " << p.rmse_units() << "\n";
  o << "noise floor: RMSE " << f3(d.floor.rmse) << " (" << d.floor.source << ")\n\n";
  o << "held-out RMSE: baseline " << f3(d.rmse_baseline_heldout) << ", extended " << f3(d.rmse_extended_heldout)
    << "; variance explained " << f3(100 * d.ve_baseline_heldout) << "% -> " << f3(100 * d.ve_extended_heldout) << "%\n";
  o << "baseline lack of fit: " << f3(d.baseline_lack_of_fit) << " x the noise floor; one residual shape shared by every item holds "
    << f3(100 * d.common_shape_share) << "% of the baseline residual" << (d.instrument_mismatch ? " (instrument mismatch)" : "") << "\n";
  o << "verdict: " << d.verdict << "\n";
  for (auto& a : d.set_aside)
    o << "\nset aside at step " << a.step << ": " << p.candidates()[a.candidate].id << ", the best fit held out (" << f3(a.rmse_before)
      << " -> " << f3(a.rmse_after) << "), " << a.reason << "\n   " << a.words << "\n";
  for (auto& c : d.causes) {
    const CandidateSpec& s = p.candidates()[c.candidate];
    o << "\n" << c.step << ". " << s.title << (s.instrument ? " [instrument]" : "") << "\n   " << c.words << "\n";
    if (!c.trial.carried_by.empty()) o << "   carried by " << c.trial.carried_by << " (" << c.trial.verdict << ")\n";
    if (!c.trial.carriers.empty()) {
      o << "   the gain is significant on its own only for:";
      for (auto& g : c.trial.carriers) o << " " << g;
      o << "\n";
    }
    for (auto& b : c.at_bound) o << "   note: in the full fit " << b << "\n";
    o << "   held-out RMSE " << f3(c.trial.rmse_before) << " -> " << f3(c.trial.rmse_after) << " (gain in MSE " << f3(c.trial.mean_gain)
      << " > threshold " << f3(c.trial.threshold) << "; " << c.trial.folds_improved << "/" << c.trial.folds
      << " groups improve); alone on the baseline: " << solo_text(p, c) << "\n";
    for (auto& g : c.by_report)
      o << "     " << d.options.report_by << " " << g.value << ": " << f3(g.rmse_before) << " -> " << f3(g.rmse_after) << "\n";
  }
  if (!d.instrument_check.empty()) {
    o << "\none instrument: instrument causes are fitted jointly on every item; fitted on each " << d.options.check_by
      << " alone as a check only:\n";
    for (auto& c : d.instrument_check) {
      o << "  " << c.cause_id << " " << c.param << ": joint " << f3(c.joint) << " +/- " << f3(c.uncertainty) << ";";
      for (auto& [v, x] : c.by_value) o << " " << v << " " << f3(x);
      o << (c.disagree ? "  (the " + d.options.check_by + "s disagree: the joint cause averages something that differs between them)" : "")
        << "\n";
    }
  }
  o << "\ncandidates tried (held-out RMSE after adding each, threshold on the MSE gain):\n";
  for (size_t s = 0; s < d.steps.size(); ++s)
    for (auto& t : d.steps[s]) {
      char b[256];
      std::snprintf(b, sizeof b, "  step %zu  %-34s %9.4g  gain %10.3g  threshold %10.3g  %d/%d  %s\n", s + 1,
                    p.candidates()[t.candidate].id.c_str(), t.rmse_after, t.mean_gain, t.threshold, t.folds_improved, t.folds,
                    t.accepted ? "accepted" : t.verdict.c_str());
      o << b;
    }
  if (auto rows = depth_comparison(p, d); !rows.empty()) {
    o << "\nlayered tissue against the surface blood filter, each alone on the baseline (held-out RMSE):\n";
    o << "  site        light   items  baseline  blood_absorption  layered_tissue\n";
    for (auto& r : rows) {
      char b[200];
      std::snprintf(b, sizeof b, "  %-10s %6s  %6d  %8.4f  %16.4f  %14.4f\n", r.site.c_str(), r.light.c_str(), r.items, r.baseline,
                    r.blood, r.layered);
      o << b;
    }
  }
  if (!d.options.report_by.empty()) {
    o << "\nheld-out RMSE by " << d.options.report_by << " (baseline -> extended):\n";
    for (auto& g : d.by_report)
      o << "  " << g.value << " (" << g.items << "): " << f3(g.rmse_before) << " -> " << f3(g.rmse_after) << ", variance explained "
        << f3(100 * g.ve_before) << "% -> " << f3(100 * g.ve_after) << "%\n";
  }
  return o.str();
}

namespace {

using ReportGroups = std::vector<std::pair<std::string, std::vector<int>>>;

// Every held-out residual of the baseline and the extended model, one row per abscissa value.
std::string residuals_csv(const DiagnoseProblem& p, const Diagnosis& d) {
  std::ostringstream o;
  o << "item,label,group,model,x,measured,predicted,residual\n";
  for (int m = 0; m < 2; ++m) {
    const CvRun& cv = m == 0 ? d.baseline_cv : d.final_cv;
    for (int i = 0; i < p.num_items(); ++i) {
      auto x = p.abscissa(i);
      const ItemFit& f = cv.heldout[i];
      for (Eigen::Index k = 0; k < f.residual.size(); ++k)
        o << i << "," << csv_quote(p.item_label(i)) << "," << csv_quote(d.folds.names[d.folds.of_item[i]]) << ","
          << (m == 0 ? "baseline" : "extended") << "," << x[k] << "," << f.measured[k] << "," << f.predicted[k] << ","
          << f.residual[k] << "\n";
    }
  }
  return o.str();
}

// Held-out RMSE per report group for the baseline and each model along the selection.
BarChart heldout_rmse_chart(const DiagnoseProblem& p, const Diagnosis& d, const ReportGroups& groups, const std::string& by) {
  BarChart b;
  b.title = "held-out RMSE by " + by + ", baseline and each accepted cause added in turn";
  b.ylabel = "RMSE (" + std::string(p.kind() == "spectra" ? "fraction of mean radiance" : "DN") + ")";
  std::vector<const CvRun*> runs = {&d.baseline_cv};
  for (auto& c : d.causes) runs.push_back(&c.trial.cv);
  for (size_t m = 0; m < runs.size(); ++m) {
    b.series_names.push_back(m == 0 ? std::string("baseline") : "+ " + p.candidates()[d.causes[m - 1].candidate].id);
    b.colors.push_back(palette_color(static_cast<int>(m)));
    std::vector<double> v;
    for (auto& [name, items] : groups) v.push_back(group_gain(p, *runs[m], *runs[m], items, name).rmse_before);
    b.values.push_back(v);
  }
  for (auto& g : groups) {
    b.categories.push_back(g.first);
    b.markers.push_back(d.floor.rmse);
  }
  b.marker_label = "noise floor";
  return b;
}

// Depth against the surface blood filter, each alone on the baseline, per site and light.
BarChart depth_chart(const std::vector<DepthRow>& rows, double floor_rmse) {
  BarChart b;
  b.title = "held-out RMSE per site and LED: baseline, + blood filter, + layered_tissue (each alone)";
  b.ylabel = "RMSE (fraction of mean radiance)";
  b.series_names = {"baseline", "+ blood_absorption", "+ layered_tissue"};
  b.colors = {palette_color(0), palette_color(1), palette_color(2)};
  b.values.resize(3);
  for (auto& r : rows) {
    b.categories.push_back(r.site + " " + r.light + " nm");
    b.values[0].push_back(r.baseline);
    b.values[1].push_back(r.blood);
    b.values[2].push_back(r.layered);
    b.markers.push_back(floor_rmse);
  }
  b.marker_label = "noise floor";
  return b;
}

// Every candidate at the first step: held-out gain against its threshold.
BarChart first_step_chart(const DiagnoseProblem& p, const Diagnosis& d) {
  BarChart b;
  b.title = "step 1: held-out MSE gain of each candidate on the baseline (dashed: threshold)";
  b.ylabel = "mean MSE gain";
  b.series_names = {"gain"};
  b.colors = {palette_color(0)};
  b.values.resize(1);
  for (auto& t : d.steps[0]) {
    b.categories.push_back(p.candidates()[t.candidate].id);
    b.values[0].push_back(t.mean_gain);
    b.markers.push_back(t.threshold);
  }
  b.marker_label = "threshold";
  return b;
}

// Mean of the held-out residuals of `items` at each abscissa value, as a series.
PlotSeries mean_residual(const DiagnoseProblem& p, const CvRun& cv, const std::vector<int>& items) {
  std::map<double, std::pair<double, int>> mean;
  for (int i : items) {
    auto x = p.abscissa(i);
    for (size_t q = 0; q < x.size(); ++q) { mean[x[q]].first += cv.heldout[i].residual[q]; mean[x[q]].second++; }
  }
  PlotSeries s;
  for (auto& [x, v] : mean) { s.x.push_back(x); s.y.push_back(v.first / v.second); }
  return s;
}

// Spectra: held-out residuals against wavelength, baseline and extended, coloured by report group,
// on one y range.
std::vector<Plot> spectra_residual_panels(const DiagnoseProblem& p, const Diagnosis& d, const ReportGroups& groups,
                                          const std::string& by) {
  std::vector<Plot> panels;
  std::set<double> xs;
  for (int i = 0; i < p.num_items(); ++i)
    for (double x : p.abscissa(i)) xs.insert(x);
  std::vector<double> xv(xs.begin(), xs.end());
  for (int m = 0; m < 2; ++m) {
    const CvRun& cv = m == 0 ? d.baseline_cv : d.final_cv;
    Plot pl;
    pl.title = (m == 0 ? "baseline (fluorophores + leak)" : model_name(p, d, d.causes.size())) + ": held-out residuals";
    pl.xlabel = "wavelength (nm)";
    pl.ylabel = "measured - predicted (fraction of mean)";
    pl.zero_line = true;
    pl.bands.push_back({xv, std::vector<double>(xv.size(), -d.floor.rmse), std::vector<double>(xv.size(), d.floor.rmse), rgb_hex(0x888888), 0.25,
                        "noise floor (+/- 1 RMSE)"});
    for (size_t g = 0; g < groups.size(); ++g) {
      for (int i : groups[g].second) {
        const auto& r = cv.heldout[i].residual;
        PlotSeries s;
        s.x = p.abscissa(i);
        s.y.assign(r.data(), r.data() + r.size());
        s.color = palette_color(static_cast<int>(g));
        s.width = 0.7;
        s.opacity = 0.35;
        pl.series.push_back(s);
      }
      PlotSeries s = mean_residual(p, cv, groups[g].second);
      s.color = palette_color(static_cast<int>(g));
      s.width = 2.5;
      s.label = "mean, " + by + " " + groups[g].first;
      pl.series.push_back(s);
    }
    panels.push_back(pl);
  }
  double lo = 1e9, hi = -1e9;
  for (auto& pl : panels)
    for (auto& s : pl.series)
      for (double v : s.y) { lo = std::min(lo, v); hi = std::max(hi, v); }
  for (auto& pl : panels) { pl.ymin = lo; pl.ymax = hi; }
  return panels;
}

// Each accepted cause's signature: mean held-out residual per report group just before and just
// after the cause was added.
std::vector<Plot> cause_signature_panels(const DiagnoseProblem& p, const Diagnosis& d, const ReportGroups& groups,
                                         const std::string& by) {
  std::vector<Plot> sig;
  const CvRun* before = &d.baseline_cv;
  for (size_t k = 0; k < d.causes.size(); ++k) {
    const CvRun* after = &d.causes[k].trial.cv;
    Plot pl;
    pl.title = std::to_string(k + 1) + ". + " + p.candidates()[d.causes[k].candidate].id;
    pl.xlabel = "wavelength (nm)";
    pl.ylabel = "mean held-out residual";
    pl.zero_line = true;
    for (size_t g = 0; g < groups.size(); ++g)
      for (int m = 0; m < 2; ++m) {
        PlotSeries s = mean_residual(p, m == 0 ? *before : *after, groups[g].second);
        s.color = palette_color(static_cast<int>(g));
        s.width = m == 0 ? 1.4 : 2.2;
        s.dashed = m == 0;
        s.label = (m == 0 ? "before, " : "after, ") + by + " " + groups[g].first;
        pl.series.push_back(s);
      }
    sig.push_back(pl);
    before = after;
  }
  return sig;
}

// A few spectra (one per site, light and report group, at most six): measured, baseline and
// extended held-out predictions.
std::vector<Plot> example_fit_panels(const DiagnoseProblem& p, const Diagnosis& d) {
  std::vector<Plot> ex;
  std::set<std::string> seen;
  auto vec = [](const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); };
  for (int i = 0; i < p.num_items() && ex.size() < 6; ++i) {
    std::string key = p.condition(i, "site") + "|" + p.condition(i, "light_nm") + "|" + p.condition(i, d.options.report_by);
    if (seen.count(key)) continue;
    seen.insert(key);
    Plot pl;
    pl.title = p.item_label(i);
    pl.xlabel = "wavelength (nm)";
    pl.ylabel = "radiance / mean";
    auto x = p.abscissa(i);
    pl.series.push_back({x, vec(d.baseline_cv.heldout[i].measured), rgb_hex(0x000000), 1.6, 1, false, true, false, "measured"});
    pl.series.push_back({x, vec(d.baseline_cv.heldout[i].predicted), palette_color(3), 1.6, 1, true, true, false, "baseline (held out)"});
    pl.series.push_back({x, vec(d.final_cv.heldout[i].predicted), palette_color(0), 1.6, 1, false, true, false, "extended (held out)"});
    ex.push_back(pl);
  }
  return ex;
}

const char* const kChannelName[3] = {"R", "G", "B"};
const int kChannelColor[3] = {1, 2, 0};  // palette.h: red, green, blue

// Camera patches, baseline and extended: held-out predicted against measured raw means
// (`scatter`), or the held-out residual per patch.
std::vector<Plot> camera_panels(const DiagnoseProblem& p, const Diagnosis& d, bool scatter) {
  std::vector<Plot> panels;
  for (int m = 0; m < 2; ++m) {
    const CvRun& cv = m == 0 ? d.baseline_cv : d.final_cv;
    Plot pl;
    if (scatter) {
      pl.title = (m == 0 ? std::string("baseline (linear sensor)") : model_name(p, d, d.causes.size())) + ", held out";
      pl.xlabel = "measured (DN)";
      pl.ylabel = "predicted (DN)";
      pl.diagonal = true;
    } else {
      pl.title = m == 0 ? "baseline" : model_name(p, d, d.causes.size());
      pl.xlabel = "patch (item index)";
      pl.ylabel = "measured - predicted (DN)";
      pl.zero_line = true;
    }
    for (int c = 0; c < 3; ++c) {
      PlotSeries s;
      s.line = false;
      s.markers = true;
      s.color = palette_color(kChannelColor[c]);
      if (scatter) s.opacity = 0.7;
      s.label = kChannelName[c];
      for (int i = 0; i < p.num_items(); ++i) {
        s.x.push_back(scatter ? cv.heldout[i].measured[c] : i);
        s.y.push_back(scatter ? cv.heldout[i].predicted[c] : cv.heldout[i].residual[c]);
      }
      pl.series.push_back(s);
    }
    panels.push_back(pl);
  }
  return panels;
}

}  // namespace

std::vector<std::string> write_diagnosis_files(const DiagnoseProblem& p, const Diagnosis& d, const ReportContext& ctx,
                                               const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir.string(), "", "cannot create the output folder: " + ec.message());
  std::vector<std::string> files;
  auto out = [&](const std::string& name, const std::string& text) {
    write_text(dir / name, text);
    files.push_back((dir / name).string());
  };
  // A figure as <stem>.svg and <stem>.png.
  auto figure = [&](const std::string& stem, const VectorPlot& plot) {
    plot.write_svg_and_png(dir / stem);
    files.push_back((dir / (stem + ".svg")).string());
    files.push_back((dir / (stem + ".png")).string());
  };
  out("report.json", diagnosis_json(p, d, ctx).dump(2) + "\n");
  out("report.txt", diagnosis_text(p, d, ctx));
  out("residuals.csv", residuals_csv(p, d));

  const ReportGroups groups = report_groups(p, d);
  const std::string by = d.options.report_by.empty() ? "all" : d.options.report_by;
  figure("heldout_rmse_by_" + slug(by), bar_chart(heldout_rmse_chart(p, d, groups, by), 760, 440));
  if (auto rows = depth_comparison(p, d); !rows.empty()) figure("layered_vs_blood", bar_chart(depth_chart(rows, d.floor.rmse), 760, 440));
  if (!d.steps.empty()) figure("candidates_step1", bar_chart(first_step_chart(p, d), 860, 460));

  if (p.kind() == "spectra") {
    figure("heldout_residuals", chart_panels(spectra_residual_panels(p, d, groups, by), 1, 900, 380,
                                             "held-out residuals (each spectrum predicted by a model fitted without its group)"));
    if (!d.causes.empty())
      figure("cause_signatures", chart_panels(cause_signature_panels(p, d, groups, by), 2, 560, 330,
                                              "what each accepted cause explains (held-out residual before -> after)"));
    figure("heldout_fits", chart_panels(example_fit_panels(p, d), 2, 560, 330, "measured spectra and held-out predictions"));
  } else {
    figure("heldout_scatter", chart_panels(camera_panels(p, d, true), 2, 520, 460, "camera: predicted vs measured raw means"));
    figure("heldout_residuals", chart_panels(camera_panels(p, d, false), 1, 900, 320, "camera: held-out residuals per patch"));
  }
  return files;
}

}  // namespace ofl
