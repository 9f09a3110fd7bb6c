// The spectra forward model of `oralfluor diagnose`: what a spectroradiometer behind the emission
// long-pass should see from tissue that is a non-negative mix of library fluorophores under the
// stated excitation light, plus the excitation light that leaks through the filters.
//
// For spectrum i under light L (radiance E(l) in W sr^-1 m^-2 nm^-1):
//   column k   = T_lp(l) * [sum_ex Phi_k(l, ex) E(ex) ex dex] / l     (photon-unit EEM, energy out)
//   leak       = measured leak of L (white target through the filters), or E_tail(l) T_lp(l)
//   y_i(l)/mean(y_i) = sum_k c_ik column_k + a_i leak + residual,  c, a >= 0 (NNLS per spectrum)
// then the instrument: Gaussian blur (stated FWHM), wavelength shift, and a detector-side flat
// offset (stray_light, one level per spectrum). Active causes
// (model_extensions.h) change these columns or add columns. Residuals are in units of the
// spectrum's mean radiance over the fit range, so spectra at different LED currents weigh alike.
#pragma once
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "renderer/diagnose/problem/diagnose_problem.h"
#include "renderer/diagnose/spectra/layered_site.h"
#include "renderer/diagnose/problem/measurement_set.h"
#include "renderer/diagnose/problem/model_extensions.h"
#include "renderer/spectral/chromophores/eem.h"
#include "renderer/spectral/spectra/optical_filter.h"
#include "renderer/spectral/spectra/spectrum.h"

namespace ofl {

struct LightEntry {
  std::map<std::string, std::string> when;  // index columns this light is for
  std::string name;
  Spectrum spectrum;                        // excitation radiance on the target
  std::optional<Spectrum> leak;             // measured light through the filters from a white target
};

enum class LeakSource { kMeasured, kComputed, kNone };

// Everything a spectra diagnosis needs besides the data (parsed from model.json).
struct SpectraModel {
  std::vector<std::string> fluorophores = {"collagen", "NADH", "FAD", "keratin", "protoporphyrin"};
  std::vector<LightEntry> lights;
  std::string nearest_column;        // when no light matches exactly, nearest in this column
  double light_floor_fraction = 1e-3;  // light below this fraction of its peak is instrument floor
  std::optional<OpticalFilter> emission_filter;    // long-pass in front of the instrument
  std::optional<OpticalFilter> excitation_filter;  // applied to the light spectra
  LeakSource leak = LeakSource::kComputed;
  double fit_min_nm = 0, fit_max_nm = 1e9;
  double grid_step_nm = 0.5;
  double instrument_fwhm_nm = 0;     // bandwidth already assumed by the baseline
  SpectraCandidateOptions candidates;
  LayeredCauseOptions layered;       // the layered_tissue cause (off unless the model has the block)
  // Spectra equal in these columns (a visit: subject, site, date) share one set of fluorophore
  // amounts (absolute: the LED spectra's measured levels relate them); empty: every spectrum its own.
  std::vector<std::string> shared_by;
  // One instrument, tissues that differ: tissue causes' global parameters (blood, shifts, widths,
  // bands) are fitted one set per value of these columns (e.g. subject), instrument causes one set
  // for all spectra. A value the fitted spectra do not have (a held-out subject) gets the mean of
  // the fitted values. Empty (the default): every cause one set for all.
  std::vector<std::string> tissue_per;
  // A column naming the instrument each spectrum was measured with: instrument causes then get one
  // set per instrument. Empty (the default): one instrument.
  std::string instrument_column;
  std::filesystem::path base_dir;    // for fluorophore files named relative to the model
};

class SpectraProblem : public DiagnoseProblem {
 public:
  SpectraProblem(SpectraSet data, SpectraModel model);

  std::string kind() const override { return "spectra"; }
  std::string rmse_units() const override { return "fraction of each spectrum's mean radiance over the fit range"; }
  int num_items() const override { return static_cast<int>(data_.spectra.size()); }
  std::string item_label(int i) const override { return data_.spectra[i].label; }
  std::string condition(int i, const std::string& column) const override;
  std::vector<double> abscissa(int i) const override { return items_[i].nm; }
  std::vector<ParamSpec> baseline_params() const override { return {}; }
  const std::vector<CandidateSpec>& candidates() const override { return candidates_; }
  std::vector<ItemFit> evaluate(const ModelState& state, const std::vector<int>& items) const override;
  Eigen::VectorXd measured(int i) const override { return items_[i].y; }
  double fallback_noise_variance() const override;
  double centred_sum_of_squares(int i) const override;
  std::vector<DerivedParam> derived_params(const CandidateSpec& c, const std::vector<ItemFit>& fits,
                                           const std::vector<int>& items) const override;
  std::string plain_words(const CandidateSpec& c, const std::vector<double>& theta, const std::vector<double>& unc,
                          const std::vector<DerivedParam>& derived) const override;
  void fill_unfitted(ModelState& state, const std::vector<int>& fitted_items) const override;
  // The unknown-band finder's estimate, when it finds one (defined in unknown_band.cpp).
  std::vector<ReportSection> report_sections(const Diagnosis& d) const override;

  // Per-tissue and per-instrument parameters (model "tissue_per", "instrument_column"): the values
  // of those columns ("" when the model has none), item i's tissue, and the parameters per value
  // of candidate c (0: one set for all).
  const std::vector<std::string>& tissue_scopes() const { return scopes_[kTissueScope].values; }
  const std::vector<std::string>& instrument_scopes() const { return scopes_[kInstrumentScope].values; }
  int scope_of(int i) const { return items_[i].scope[kTissueScope]; }
  int params_per_scope(int c) const { return scope_params_[c]; }

  // The columns of item i under `state` (before the NNLS), in measured units divided by the
  // spectrum's mean: used to synthesise data with known amplitudes.
  struct Design {
    Eigen::MatrixXd A;
    std::vector<std::string> names;
  };
  Design design(const ModelState& state, int item) const;
  // The instrument part of the model applied to a tissue radiance on the grid (W sr^-1 m^-2 nm^-1,
  // e.g. a rendered patch under item's light; closing the loop, render_loop.h): the emission
  // long-pass (with the state's edge shift), the item's leak columns as in the baseline (and
  // longpass_leak when active), then the state's instrument causes (bandwidth, wavelength shift,
  // stray light), sampled at the item's fit wavelengths. Column 0 ("radiance") is the radiance;
  // the state's tissue causes (blood, broadening, extra fluorophores) are ignored: the radiance
  // carries them.
  Design instrument_design(const ModelState& state, int item, const std::vector<double>& radiance) const;
  // Excitation radiance of light `light` on the grid as the model uses it: after the excitation
  // filter, with the instrument floor beyond the LED band removed.
  const std::vector<double>& excitation(int light) const { return lights_[light].e_tail; }
  double mean_radiance(int i) const { return items_[i].mean; }
  const SpectraSet& data() const { return data_; }
  const SpectraModel& model() const { return model_; }
  const WavelengthGrid& grid() const { return grid_; }
  // Names of the fluorophores the model knows: the baseline's, then the extra candidates'.
  const std::vector<std::string>& fluorophore_names() const { return eem_names_; }
  const GridEem& fluorophore_eem(int k) const { return eems_[k]; }
  int light_of(int i) const { return items_[i].light; }
  // The layered_tissue cause's sites (empty when the model has none) and item i's site (-1: none).
  const std::vector<std::shared_ptr<const LayeredSite>>& layered_sites() const { return sites_; }
  int site_of(int i) const { return items_[i].site; }

 private:
  struct Item {
    int light = -1;
    int site = -1;           // index into sites_ (layered_tissue), -1 when its site has no stack
    std::array<int, 2> scope = {0, 0};  // index into scopes_[kTissueScope] and scopes_[kInstrumentScope]
    std::vector<double> nm;  // fit wavelengths
    Eigen::VectorXd y;       // measured / mean over the fit range
    double mean = 1;
    double noise = 0;        // high-frequency scatter of y (second differences), per sample
    std::vector<int> lo;     // grid interpolation: index and weight
    std::vector<double> w;
  };
  struct LightBasis {
    std::vector<double> e;        // radiance on the grid (after the excitation filter)
    std::vector<double> e_tail;   // e with the instrument floor beyond the LED band removed
    std::vector<std::vector<double>> fluor;  // per EEM: emission column without blood and filter
    std::vector<double> leak;     // measured leak on the grid (empty if none)
  };
  struct Effects;
  Effects decode(const ModelState& s, const std::array<int, 2>& scope) const;
  void replicate_scoped_params();
  std::string scope_key(const MeasuredSpectrum& s, int kind) const;
  std::string plain_words_one(const CandidateSpec& c, const std::vector<double>& theta, const std::vector<double>& unc,
                              const std::vector<DerivedParam>& derived) const;
  std::vector<std::vector<double>> grid_columns(int light, int site, const Effects& fx, std::vector<std::string>* names) const;
  void add_layered_candidate();
  // Steps of the constructor: the candidate list for the data's span [lo, hi], one light's basis
  // on the grid, and the fit item of data_.spectra[index].
  void make_candidates(double lo, double hi);
  LightBasis light_basis(const LightEntry& light) const;
  Item make_item(int index) const;
  std::string visit_of(int i) const;
  void fit_visit(const std::vector<int>& items, const std::vector<size_t>& group, const std::vector<Eigen::MatrixXd>& A,
                 const std::vector<std::string>& names, std::vector<ItemFit>& out) const;
  void longpass(const Effects& fx, std::vector<double>& tlp, std::vector<double>& block) const;
  void add_leak_columns(int light, const Effects& fx, const std::vector<double>& tlp, const std::vector<double>& block,
                        std::vector<std::vector<double>>& cols, std::vector<std::string>* names) const;
  void apply_instrument(std::vector<std::vector<double>>& cols, const Effects& fx) const;
  void add_offset_column(const Effects& fx, std::vector<std::vector<double>>& cols, std::vector<std::string>* names) const;
  int eem_index(const std::string& name) const;
  void shape_emission(int k, const Effects& fx, std::vector<double>& col) const;
  Eigen::MatrixXd sample(const std::vector<std::vector<double>>& cols, const Item& it) const;

  SpectraSet data_;
  SpectraModel model_;
  WavelengthGrid grid_;
  std::vector<std::string> eem_names_;  // baseline fluorophores, then extra candidates
  std::vector<GridEem> eems_;
  std::vector<LightBasis> lights_;
  std::vector<Item> items_;
  std::vector<CandidateSpec> candidates_;
  std::vector<std::shared_ptr<const LayeredSite>> sites_;
  std::vector<int> fit_grid_;  // grid indices inside the fit range
  // One set of parameters per value of some columns: tissue causes per "tissue_per", instrument
  // causes per "instrument_column" (no columns: one set, value "").
  struct Scopes {
    std::vector<std::string> columns;
    std::vector<std::string> values = {""};
  };
  enum { kTissueScope = 0, kInstrumentScope = 1 };
  std::array<Scopes, 2> scopes_;
  std::vector<int> scope_params_;  // per candidate: parameters per scope value (0: one set)
  std::vector<int> scope_kind_;    // per candidate: which scopes its copies follow
  SpectraRange range_;         // wavelengths fitted (fit range within the data)
};

// Whether the longpass_leak candidate can be offered: whenever there is an emission long-pass,
// measured leak or not (its column is computed from each light's spectrum and the long-pass).
bool leak_candidate_possible(const SpectraModel& m);
// The layered_tissue block's site column must be an index column holding at least one of its
// sites: otherwise no spectrum gets a stack and the cause would report zero gain at every site,
// which reads like a finding. InputError naming /layered_tissue/site_column of the "model".
void check_site_column(const SpectraSet& data, const LayeredCauseOptions& o);
// The layered_tissue cause's parameters of one site (thickness mm, oxy and deoxy blood volume
// fractions) as the stack's (thickness, blood fraction, saturation; saturation 1 without blood).
std::array<double, 3> layered_theta(const double* site_params);
// Emission peak (energy units) of a fluorophore under its most efficient excitation.
double emission_peak_nm(const GridEem& e);
// A Gaussian band on the grid, unit area (per nm x step).
std::vector<double> gaussian_band(const WavelengthGrid& g, double center_nm, double fwhm_nm);
// An emission band on the grid, unit area (per nm x step): log-normal in wavenumber (Siano &
// Metzler) whose energy per nm peaks at peak_nm, FWHM H = 1e7 fwhm_nm / peak_nm^2 in wavenumber,
// and `asymmetry` = low- over high-wavenumber half width (> 1: a red tail; 1: Gaussian in
// wavenumber).
std::vector<double> lognormal_band(const WavelengthGrid& g, double peak_nm, double fwhm_nm, double asymmetry);
// Linear interpolation in a table (x increasing), constant beyond its ends.
double piecewise_linear(const std::vector<double>& x, const std::vector<double>& y, double at);

// The light entry for a row of conditions: all `when` columns equal, except `nearest` (if set)
// which picks the closest number. -1 when none fits.
int match_light(const std::vector<LightEntry>& lights, const std::map<std::string, std::string>& row,
                const std::string& nearest);

}  // namespace ofl
