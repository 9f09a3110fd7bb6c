// Closing the loop of `oralfluor diagnose`: the diagnosis' accepted tissue
// causes become tissue material options, a flat patch of the material is rendered under each
// measured spectrum's LED spectrum, and the rendered radiance, through the diagnosis' instrument
// model, is compared with the measured spectrum. Held out like the diagnosis: for each
// cross-validation fold the global parameters (broadening, blood, bandwidth, ...) are the ones the
// diagnosis fitted without that fold.
//
// Two ways to get concentrations (renderer/diagnose/spectra/render_loop.h):
//   spectrum  the diagnosis' own protocol: every held-out spectrum's fluorophore amplitudes fitted
//             to that spectrum (the diagnosis refits its local amplitudes on held-out data too);
//   site      a fixed material per site (tongue, lip) fitted to the training folds' spectra of that
//             site: nothing but a scale and the leak amplitude is fitted to the held-out spectrum;
//   subject_site  the same per subject and site (the site's when the training folds hold no
//             spectrum of that subject and site).
// Both materials of a comparison go through the same instrument (the extended model's: long-pass,
// measured leak, accepted instrument causes), so only the material differs.
//
// Usage: diagnose_loop [input] [model] [--out dir] [--spp N] [--res N] [--threads N]
//                      [--protocol spectrum,site,subject_site|all] [--plot file.svg] [--json]
// Defaults: assets/measurements/oe_tongue_lip scenes/diagnose/oe_tongue_lip.json --out out/diagnose_loop
#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/diagnose/selection/cross_validation.h"
#include "renderer/diagnose/diagnose_model.h"
#include "renderer/diagnose/spectra/render_loop.h"
#include "renderer/plot/charts.h"
#include "renderer/numerics/nnls.h"

using namespace ofl;
namespace fs = std::filesystem;

namespace {

struct Args {
  std::string input = "assets/measurements/oe_tongue_lip";
  std::string model = "scenes/diagnose/oe_tongue_lip.json";
  std::string out = "out/diagnose_loop";
  std::string protocol = "all";
  std::set<std::string> protocols;
  std::string plot;
  int threads = 0;
  bool json = false;
  PatchRenderOptions render;
};

Args parse_args(int argc, char** argv) {
  Args a;
  int positional = 0;
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) { std::fprintf(stderr, "error: %s needs a value\n", s.c_str()); std::exit(2); }
      return argv[++i];
    };
    if (s == "--out" || s == "-o") a.out = next();
    else if (s == "--spp") a.render.spp = std::atoi(next().c_str());
    else if (s == "--res") a.render.resolution = std::atoi(next().c_str());
    else if (s == "--threads") a.threads = std::atoi(next().c_str());
    else if (s == "--protocol") a.protocol = next();
    else if (s == "--plot") a.plot = next();
    else if (s == "--json") a.json = true;
    else if (s == "--help" || s == "-h") {
      std::printf("diagnose_loop [input] [model] [--out dir] [--spp N] [--res N] [--threads N] [--protocol spectrum,site,subject_site|all] [--plot f.svg] [--json]\n");
      std::exit(0);
    } else if (!s.empty() && s[0] == '-') {
      std::fprintf(stderr, "error: unknown option %s\n", s.c_str());
      std::exit(2);
    } else if (positional == 0) { a.input = s; ++positional; }
    else if (positional == 1) { a.model = s; ++positional; }
    else { std::fprintf(stderr, "error: unexpected argument %s\n", s.c_str()); std::exit(2); }
  }
  for (size_t b = 0, e; b <= a.protocol.size(); b = e + 1) {
    e = a.protocol.find(',', b);
    if (e == std::string::npos) e = a.protocol.size();
    std::string one = a.protocol.substr(b, e - b);
    if (one != "spectrum" && one != "site" && one != "subject_site" && one != "all") {
      std::fprintf(stderr, "error: --protocol takes spectrum, site, subject_site (comma-separated) or all\n");
      std::exit(2);
    }
    if (one == "all") a.protocols = {"spectrum", "site", "subject_site"};
    else a.protocols.insert(one);
  }
  return a;
}

// The comparison of the diagnosis' own model with concentrations held fixed: the same fit as
// compare_rendered, with the model's tissue columns x concentrations in place of the render.
ItemFit compare_model(const SpectraProblem& p, const ModelState& state, int item, const std::map<std::string, double>& conc) {
  SpectraProblem::Design d = p.design(state, item);
  Eigen::MatrixXd A(d.A.rows(), 1);
  A.setZero();
  std::vector<int> inst;
  for (size_t k = 0; k < d.names.size(); ++k) {
    auto it = conc.find(d.names[k]);
    if (d.names[k] == "leak" || d.names[k] == "longpass_leak") inst.push_back(static_cast<int>(k));
    else if (it != conc.end()) A.col(0) += d.A.col(static_cast<Eigen::Index>(k)) * it->second;
  }
  Eigen::MatrixXd B(d.A.rows(), 1 + static_cast<Eigen::Index>(inst.size()));
  B.col(0) = A.col(0);
  for (size_t k = 0; k < inst.size(); ++k) B.col(static_cast<Eigen::Index>(k + 1)) = d.A.col(inst[k]);
  Eigen::VectorXd y = p.measured(item);
  NnlsResult r = nnls(B, y);
  ItemFit f;
  f.measured = y;
  f.predicted = B * r.x;
  f.residual = y - f.predicted;
  f.locals["scale"] = r.x[0];
  return f;
}

std::string preset_for(const std::string& site) {
  std::error_code ec;
  if (!site.empty() && fs::exists(asset_root() / "tissues" / (site + ".json"), ec)) return site;
  return "mucosa";
}

// Per-protocol results: per item, the rendered and the model comparison of both materials.
struct ProtocolResult {
  std::string name;
  std::vector<ItemFit> base, ext, base_model, ext_model;
  std::vector<std::vector<double>> base_radiance, ext_radiance;  // per item (for plots)
  std::vector<nlohmann::json> base_material, ext_material;
  int renders = 0;
  double seconds = 0;
};

struct Row {
  std::string group;
  int items = 0;
  double base = 0, ext = 0, base_model = 0, ext_model = 0;
};

std::vector<Row> rows_by(const DiagnoseProblem& p, const ProtocolResult& r, const std::string& column) {
  std::map<std::string, std::vector<int>> by;
  std::vector<int> all;
  for (int i = 0; i < p.num_items(); ++i) {
    all.push_back(i);
    if (!column.empty()) by[p.condition(i, column)].push_back(i);
  }
  std::vector<Row> rows;
  auto row = [&](const std::string& g, const std::vector<int>& items) {
    Row w;
    w.group = g;
    w.items = static_cast<int>(items.size());
    w.base = pooled_rmse(r.base, items);
    w.ext = pooled_rmse(r.ext, items);
    w.base_model = pooled_rmse(r.base_model, items);
    w.ext_model = pooled_rmse(r.ext_model, items);
    return w;
  };
  for (auto& [g, items] : by) rows.push_back(row(g, items));
  rows.push_back(row("all", all));
  return rows;
}

}  // namespace

int run(int argc, char** argv) {
  Args args = parse_args(argc, argv);
  std::optional<tbb::global_control> threads;
  if (args.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, args.threads);
  auto t0 = std::chrono::steady_clock::now();

  DiagnoseModelFile mf = load_diagnose_model(args.model);
  SpectraSet data = read_spectra_index(args.input, mf.file_column, mf.select);
  SpectraProblem p(std::move(data), mf.spectra);
  const SelectionOptions& sel = mf.selection;
  const std::string report_by = sel.report_by.empty() ? "subject" : sel.report_by;

  // 1. The diagnosis, as `oralfluor diagnose` runs it.
  std::fprintf(stderr, "diagnosing %d spectra ...\n", p.num_items());
  Diagnosis d = diagnose(p, sel);
  double t_diag = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::string causes;
  for (auto& c : d.causes) causes += (causes.empty() ? "" : ", ") + p.candidates()[c.candidate].id;
  std::fprintf(stderr, "diagnosis: %s; held-out RMSE %.4f -> %.4f (%.0f s)\n", causes.c_str(), d.rmse_baseline_heldout,
               d.rmse_extended_heldout, t_diag);

  const Folds& folds = d.folds;
  std::vector<ModelState> ext(folds.count()), inst(folds.count());
  fs::create_directories(args.out);
  std::vector<std::string> fold_report(folds.count());
  std::vector<std::vector<int>> train(folds.count()), test(folds.count());
  for (int i = 0; i < p.num_items(); ++i)
    for (int f = 0; f < folds.count(); ++f) (folds.of_item[i] == f ? test[f] : train[f]).push_back(i);
  for (int f = 0; f < folds.count(); ++f) {
    ext[f] = d.final_cv.fold_states[f];
    inst[f] = instrument_only(p, ext[f]);
    fold_report[f] = fs::absolute(fs::path(args.out) / ("fold" + std::to_string(f + 1) + "_report.json")).string();
    write_file_atomic(fold_report[f], state_report(p, ext[f], train[f]).dump(2) + "\n");
  }
  // The diagnosis' own numbers with the instrument of the extended model for both materials.
  std::vector<ItemFit> diag_base(p.num_items()), diag_ext(p.num_items());
  for (int f = 0; f < folds.count(); ++f) {
    auto b = p.evaluate(inst[f], test[f]);
    auto e = p.evaluate(ext[f], test[f]);
    for (size_t k = 0; k < test[f].size(); ++k) {
      diag_base[test[f][k]] = b[k];
      diag_ext[test[f][k]] = e[k];
    }
  }

  // 2. Render.
  std::vector<ProtocolResult> results;
  auto run_protocol = [&](const std::string& name) {
    ProtocolResult r;
    r.name = name;
    const int n = p.num_items();
    r.base.resize(n); r.ext.resize(n); r.base_model.resize(n); r.ext_model.resize(n);
    r.base_radiance.resize(n); r.ext_radiance.resize(n); r.base_material.resize(n); r.ext_material.resize(n);
    auto t = std::chrono::steady_clock::now();
    for (int f = 0; f < folds.count(); ++f) {
      // Materials per held-out item: its own fit, or its site's fit on the training folds.
      std::map<std::string, std::pair<std::map<std::string, double>, std::map<std::string, double>>> site_conc;
      std::map<std::string, std::vector<double>> cache;  // site protocol: one render per material and light
      for (int i : test[f]) {
        std::string site = p.condition(i, "site");
        std::map<std::string, double> cb, ce;
        if (name == "spectrum") {
          cb = item_concentrations(p, inst[f], i);
          ce = item_concentrations(p, ext[f], i);
        } else {
          // One material per site (or per subject and site) from the training folds' spectra.
          const bool by_subject = name == "subject_site";
          std::string key = by_subject ? p.condition(i, report_by) + "|" + site : site;
          auto it = site_conc.find(key);
          if (it == site_conc.end()) {
            std::vector<int> tr;
            for (int j : train[f])
              if (p.condition(j, "site") == site && (!by_subject || p.condition(j, report_by) == p.condition(i, report_by))) tr.push_back(j);
            if (tr.empty())  // no training spectrum of this subject and site: the site's
              for (int j : train[f])
                if (p.condition(j, "site") == site) tr.push_back(j);
            if (tr.empty()) tr = train[f];
            it = site_conc.emplace(key, std::make_pair(joint_concentrations(p, inst[f], tr), joint_concentrations(p, ext[f], tr))).first;
          }
          cb = it->second.first;
          ce = it->second.second;
        }
        std::string preset = preset_for(site);
        r.base_material[i] = tissue_material(preset, cb);
        r.ext_material[i] = fitted_material(p, ext[f], i, preset, ce, fold_report[f]);  // a layered stack when fitted
        auto render_cached = [&](const nlohmann::json& mat, const std::string& tag) {
          if (name == "spectrum") { ++r.renders; return render_item_patch(p, i, mat, args.render); }
          std::string key = tag + "|" + site + "|" + (name == "subject_site" ? p.condition(i, report_by) : "") + "|" +
                            std::to_string(p.light_of(i));
          auto c = cache.find(key);
          if (c == cache.end()) {
            ++r.renders;
            c = cache.emplace(key, render_item_patch(p, i, mat, args.render)).first;
          }
          return c->second;
        };
        r.base_radiance[i] = render_cached(r.base_material[i], "base");
        r.ext_radiance[i] = render_cached(r.ext_material[i], "ext");
        r.base[i] = compare_rendered(p, inst[f], i, r.base_radiance[i]);
        r.ext[i] = compare_rendered(p, ext[f], i, r.ext_radiance[i]);
        r.base_model[i] = compare_model(p, inst[f], i, cb);
        r.ext_model[i] = compare_model(p, ext[f], i, ce);
        std::fprintf(stderr, "  %s fold %d %-40s rendered %.4f -> %.4f  (model %.4f -> %.4f)\n", name.c_str(), f + 1,
                     p.item_label(i).c_str(), std::sqrt(r.base[i].residual.squaredNorm() / r.base[i].residual.size()),
                     std::sqrt(r.ext[i].residual.squaredNorm() / r.ext[i].residual.size()),
                     std::sqrt(r.base_model[i].residual.squaredNorm() / r.base_model[i].residual.size()),
                     std::sqrt(r.ext_model[i].residual.squaredNorm() / r.ext_model[i].residual.size()));
      }
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
    results.push_back(std::move(r));
  };
  for (std::string name : {"spectrum", "site", "subject_site"})
    if (args.protocols.count(name)) run_protocol(name);

  // 3. Report.
  std::vector<int> all(p.num_items());
  for (int i = 0; i < p.num_items(); ++i) all[i] = i;
  nlohmann::json out;
  out["input"] = args.input;
  out["model"] = args.model;
  out["render"] = {{"resolution", args.render.resolution}, {"spp", args.render.spp}, {"seed", args.render.seed}};
  out["causes"] = causes;
  out["diagnosis"] = {{"rmse_baseline_heldout", d.rmse_baseline_heldout},
                      {"rmse_extended_heldout", d.rmse_extended_heldout},
                      {"gain", d.rmse_baseline_heldout / d.rmse_extended_heldout},
                      {"rmse_baseline_same_instrument_heldout", pooled_rmse(diag_base, all)},
                      {"rmse_extended_same_instrument_heldout", pooled_rmse(diag_ext, all)},
                      {"gain_same_instrument", pooled_rmse(diag_base, all) / pooled_rmse(diag_ext, all)},
                      {"seconds", t_diag}};
  // Per report_by value of the diagnosis (as reported, and with the same instrument).
  std::map<std::string, std::vector<int>> groups;
  for (int i = 0; i < p.num_items(); ++i) groups[p.condition(i, report_by)].push_back(i);
  nlohmann::json diag_by = nlohmann::json::array();
  for (auto& [g, items] : groups) {
    double rb = pooled_rmse(d.baseline_cv.heldout, items), re = pooled_rmse(d.final_cv.heldout, items);
    diag_by.push_back({{report_by, g}, {"items", items.size()}, {"rmse_baseline_heldout", rb}, {"rmse_extended_heldout", re},
                       {"rmse_baseline_same_instrument_heldout", pooled_rmse(diag_base, items)}});
  }
  out["diagnosis"]["by_" + report_by] = diag_by;

  // The tables go to stdout, or to stderr when stdout carries the JSON.
  FILE* txt = args.json ? stderr : stdout;
  std::fprintf(txt, "diagnose_loop: %s, %d spectra, causes: %s\n", args.input.c_str(), p.num_items(), causes.c_str());
  std::fprintf(txt, "diagnosis (held out, %d folds): baseline %.4f -> extended %.4f, gain %.2fx as reported; "
                    "with the extended model's instrument for both: %.4f -> %.4f, gain %.2fx\n",
                    folds.count(), d.rmse_baseline_heldout, d.rmse_extended_heldout, d.rmse_baseline_heldout / d.rmse_extended_heldout,
                    pooled_rmse(diag_base, all), pooled_rmse(diag_ext, all), pooled_rmse(diag_base, all) / pooled_rmse(diag_ext, all));
  nlohmann::json protos = nlohmann::json::object();
  for (auto& r : results) {
    std::fprintf(txt, "\nprotocol %s (%d renders, %.0f s; %dx%d px x %d spp each)\n", r.name.c_str(), r.renders, r.seconds,
                      args.render.resolution, args.render.resolution, args.render.spp);
    std::fprintf(txt, "%-10s %5s | %-26s %7s | %-26s %7s | %-26s\n", report_by.c_str(), "items", "rendered: baseline -> ext", "gain",
                      "model: baseline -> ext", "gain", "diagnosis as reported");
    nlohmann::json rows = nlohmann::json::array();
    for (auto& w : rows_by(p, r, report_by)) {
      std::vector<int> items = w.group == "all" ? all : groups[w.group];
      double rb = pooled_rmse(d.baseline_cv.heldout, items), re = pooled_rmse(d.final_cv.heldout, items);
      std::fprintf(txt, "%-10s %5d | %.4f -> %.4f %12s %6.2fx | %.4f -> %.4f %12s %6.2fx | %.4f -> %.4f (%.2fx)\n", w.group.c_str(), w.items,
                        w.base, w.ext, "", w.base / w.ext, w.base_model, w.ext_model, "", w.base_model / w.ext_model, rb, re, rb / re);
      rows.push_back({{report_by, w.group}, {"items", w.items},
                      {"rendered_baseline", w.base}, {"rendered_extended", w.ext}, {"rendered_gain", w.base / w.ext},
                      {"model_baseline", w.base_model}, {"model_extended", w.ext_model}, {"model_gain", w.base_model / w.ext_model},
                      {"diagnosis_baseline", rb}, {"diagnosis_extended", re}, {"diagnosis_gain", rb / re},
                      {"diagnosis_baseline_same_instrument", pooled_rmse(diag_base, items)}});
    }
    // The same by LED (where a fixed material misses most).
    nlohmann::json by_light = nlohmann::json::array();
    for (auto& w : rows_by(p, r, "light_nm")) {
      if (w.group == "all") continue;
      std::fprintf(txt, "  light %s nm: %2d items, rendered %.4f -> %.4f (%.2fx)\n", w.group.c_str(), w.items, w.base, w.ext, w.base / w.ext);
      by_light.push_back({{"light_nm", w.group}, {"items", w.items}, {"rendered_baseline", w.base}, {"rendered_extended", w.ext}});
    }
    // Rendered against the model's prediction with the same concentrations: the renderer's share.
    double dd = 0;
    long nn = 0;
    for (int i = 0; i < p.num_items(); ++i) {
      dd += (r.ext[i].predicted - r.ext_model[i].predicted).squaredNorm() + (r.base[i].predicted - r.base_model[i].predicted).squaredNorm();
      nn += 2 * r.ext[i].predicted.size();
    }
    std::fprintf(txt, "rendered vs model prediction (same concentrations): RMS difference %.4f\n", std::sqrt(dd / nn));
    protos[r.name] = {{"by_" + report_by, rows}, {"by_light_nm", by_light}, {"renders", r.renders}, {"seconds", r.seconds},
                      {"rms_rendered_minus_model", std::sqrt(dd / nn)}};
    // Per-item table.
    std::ostringstream csv;
    csv << "item," << report_by << ",site,light_nm,led_current_mA,fold,rendered_baseline,rendered_extended,model_baseline,model_extended\n";
    auto rm = [](const ItemFit& f) { return std::sqrt(f.residual.squaredNorm() / f.residual.size()); };
    for (int i = 0; i < p.num_items(); ++i)
      csv << p.item_label(i) << "," << p.condition(i, report_by) << "," << p.condition(i, "site") << "," << p.condition(i, "light_nm")
          << "," << p.condition(i, "led_current_mA") << "," << folds.of_item[i] + 1 << "," << rm(r.base[i]) << "," << rm(r.ext[i]) << ","
          << rm(r.base_model[i]) << "," << rm(r.ext_model[i]) << "\n";
    write_file_atomic(fs::path(args.out) / ("items_" + r.name + ".csv"), csv.str());
    // Materials of the site protocol, for users.
    if (r.name == "site") {
      nlohmann::json mats = nlohmann::json::array();
      for (int f = 0; f < folds.count(); ++f)
        for (int i : test[f]) {
          bool seen = false;
          for (auto& m : mats) seen = seen || (m["fold"] == f + 1 && m["site"] == p.condition(i, "site"));
          if (!seen)
            mats.push_back({{"fold", f + 1}, {"site", p.condition(i, "site")}, {"baseline", r.base_material[i]}, {"extended", r.ext_material[i]}});
        }
      write_file_atomic(fs::path(args.out) / "materials_site.json", mats.dump(2) + "\n");
    }
  }
  out["protocols"] = protos;

  // 4. The plot: a tongue and a lip spectrum (the highest-current 405 nm spectrum of the first
  //    subject, else the first of the site), measured vs rendered baseline vs rendered extended.
  if (!args.plot.empty() && !results.empty()) {
    std::vector<Plot> panels;
    for (auto& r : results)
      for (std::string site : {"tongue", "lip"}) {
        if (r.name == "subject_site") continue;  // two protocols are enough for the picture
        int pick = -1;
        double best = -1;
        for (int i = 0; i < p.num_items(); ++i) {
          if (p.condition(i, "site") != site) continue;
          double cur = std::atof(p.condition(i, "led_current_mA").c_str());
          double score = (p.condition(i, "light_nm") == "405" ? 1e6 : 0) + (p.condition(i, report_by) == groups.begin()->first ? 1e5 : 0) + cur;
          if (score > best) { best = score; pick = i; }
        }
        if (pick < 0) continue;
        Plot pl;
        auto rm = [](const ItemFit& f) { return std::sqrt(f.residual.squaredNorm() / f.residual.size()); };
        char title[256];
        std::snprintf(title, sizeof title, "%s (%s): %s, %s nm %s mA", site.c_str(), r.name == "spectrum" ? "own fit" : "site material",
                      p.condition(pick, report_by).c_str(), p.condition(pick, "light_nm").c_str(), p.condition(pick, "led_current_mA").c_str());
        pl.title = title;
        pl.xlabel = "wavelength (nm)";
        pl.ylabel = "radiance / mean";
        auto nm = p.abscissa(pick);
        auto vec = [](const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); };
        PlotSeries m;
        m.x = nm;
        m.y = vec(r.ext[pick].measured);
        m.color = rgb_hex(0x000000);
        m.width = 2.0;
        m.label = "measured";
        char lb[128], le[128];
        std::snprintf(lb, sizeof lb, "baseline, RMSE %.3f", rm(r.base[pick]));
        std::snprintf(le, sizeof le, "extended, RMSE %.3f", rm(r.ext[pick]));
        PlotSeries b;
        b.x = nm;
        b.y = vec(r.base[pick].predicted);
        b.color = rgb_hex(0xd62728);
        b.dashed = true;
        b.label = lb;
        PlotSeries e;
        e.x = nm;
        e.y = vec(r.ext[pick].predicted);
        e.color = rgb_hex(0x1f77b4);
        e.width = 1.8;
        e.label = le;
        pl.series = {m, b, e};
        pl.ymin = 0;
        panels.push_back(pl);
      }
    fs::path pp(args.plot);
    if (pp.has_parent_path()) fs::create_directories(pp.parent_path());
    write_file_atomic(pp, chart_panels(panels, 2, 560, 340,
                                       "Measured vs rendered flat patch of the baseline and the extended material (held out, same instrument)")
                              .to_svg());
    std::fprintf(stderr, "wrote %s\n", args.plot.c_str());
  }
  out["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_file_atomic(fs::path(args.out) / "loop.json", out.dump(2) + "\n");
  if (args.json) std::printf("%s\n", out.dump(2).c_str());
  std::fprintf(stderr, "wrote %s\n", (fs::path(args.out) / "loop.json").string().c_str());
  return 0;
}

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.describe().c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error: %s\n", e.what());
    return 1;
  }
}
