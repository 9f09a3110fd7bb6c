// {"type": "tissue", "preset": "tongue" | "lip" | "mucosa" | "teeth", ...overrides} and the alias
// {"type": "teeth", ...}: oral tissue built from shipped measurements. A preset
// (assets/tissues/<preset>.json) is a coated fluorescent material with measured reflectance and
// calibrated fluorophore concentrations (each preset says how it was calibrated). Overrides:
//   "reflectance": <spectrum>                 replaces the base reflectance
//   "concentrations": {"FAD": 4e-4, ...}      sets (or adds) library fluorophores
//   "fluorescence_scale": 0.5                 multiplies every concentration
//   "textures": {"protoporphyrin": "patch.png" | {"file": ..., "offset": 1, "scale": -0.5}}
//   "extra_fluorophores": [<fluorophore layer>, ...]   appended as written (e.g. a second
//                                             protoporphyrin layer mapped to a lesion)
//   "coating": {"ior": 1.33, "roughness": 0.25} | false
//   "blood": {"oxy_uM_cm": 3.8, "deoxy_uM_cm": 2.3, "excitation_path_factor": 1}
//          | {"thickness_um": 25, "saturation": 0.7, "volume_fraction": 1, "hemoglobin_g_per_L": 150}
//                                             a Beer-Lambert hemoglobin layer over the base: the
//                                             light leaving is attenuated by 10^-OD(em), the light
//                                             entering by 10^-f OD(ex) (f = excitation_path_factor)
//   "emission_broadening_fwhm_nm": 52          every fluorophore's emission blurred by a Gaussian of
//                                             this FWHM (tissue bands are broader than the library's
//                                             solution spectra); photons the blur moves to or below
//                                             the excitation wavelength are dropped, as in the
//                                             diagnosis' model
//   "diagnosis": "report.json"                the tissue causes an `oralfluor diagnose --json` report
//                                             accepted: blood absorption (as "blood"), emission
//                                             broadening (as "emission_broadening_fwhm_nm") and
//                                             extra fluorophores (concentration set so that their
//                                             share of the fluorescence is the reported one, unless
//                                             "concentrations" names the fluorophore: a value given
//                                             there wins). "blood" and "emission_broadening_fwhm_nm"
//                                             given as well override the report's.
#include <filesystem>

#include <algorithm>
#include <optional>
#include <set>

#include "materials/material_parser.h"
#include "materials/corrections/diagnosis_corrections.h"
#include "renderer/spectral/chromophores/hemoglobin.h"
#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"

namespace ofl {

namespace {

BloodAbsorber parse_blood(const JsonNode& b) {
  b.check_keys({"oxy_uM_cm", "deoxy_uM_cm", "thickness_um", "saturation", "volume_fraction", "hemoglobin_g_per_L",
                "excitation_path_factor"});
  BloodAbsorber a;
  if (b.has("thickness_um")) {
    if (b.has("oxy_uM_cm") || b.has("deoxy_uM_cm")) b.fail("give either oxy_uM_cm/deoxy_uM_cm or thickness_um/saturation");
    a = BloodAbsorber::whole_blood(b.at("thickness_um").number(0.0, 1e4), b.number_or("saturation", 0.7, 0.0, 1.0),
                                   b.number_or("volume_fraction", 1.0, 0.0, 1.0), b.number_or("hemoglobin_g_per_L", 150.0, 0.0, 500.0));
  } else {
    a.oxy_uM_cm = b.number_or("oxy_uM_cm", 0.0, 0.0, 1e6);
    a.deoxy_uM_cm = b.number_or("deoxy_uM_cm", 0.0, 0.0, 1e6);
  }
  a.excitation_path_factor = b.number_or("excitation_path_factor", 1.0, 0.0, 10.0);
  return a;
}

// Sets the concentration of each extra fluorophore named by a diagnosis so that its share of the
// fluorescence photons (470-750 nm, the diagnosis' fit range) under a 405 nm LED (15 nm FWHM) is
// the share the diagnosis measured: c_x S_x / (S_rest + c_x S_x) = f.
void set_extra_shares(Material& m, const TissueCorrections& corr, MaterialContext& ctx, const std::set<std::string>& given) {
  const WavelengthGrid& g = ctx.grid;
  auto led = tabulate(gaussian_spectrum(405, 15), g);
  auto signal = [&](const FluorophoreLayer& f) {
    auto e = (*ctx.eems)[f.eem].apply(led);
    double s = 0;
    for (int i = 0; i < g.size(); ++i)
      if (g.wavelength(i) >= 470 && g.wavelength(i) <= 750) s += e[i];
    return s;
  };
  double rest = 0;
  for (auto& f : m.fluorophores) rest += f.concentration * signal(f);
  for (auto& x : corr.extra_fluorophores) {
    if (given.count(x.name)) continue;  // the user's concentration wins
    for (auto& f : m.fluorophores) {
      if (f.name != x.name || f.concentration != 0) continue;
      double sx = signal(f);
      double share = std::clamp(x.mean_fraction, 0.0, 0.95);
      if (sx > 0) f.concentration = share * rest / ((1 - share) * sx);
    }
  }
}

}  // namespace

namespace {

// The preset's file under assets/tissues/; an unknown name lists the presets there.
std::filesystem::path preset_file(const JsonNode& n, const std::string& forced_preset) {
  std::string preset = forced_preset.empty() ? n.at("preset").string() : n.string_or("preset", forced_preset);
  auto file = asset_root() / "tissues" / (preset + ".json");
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    std::string have;
    for (auto& e : std::filesystem::directory_iterator(asset_root() / "tissues", ec))
      if (e.path().extension() == ".json") have += (have.empty() ? "" : ", ") + e.path().stem().string();
    (forced_preset.empty() ? n.at("preset") : n).fail("no tissue preset \"" + preset + "\" (have: " + have + ")");
  }
  return file;
}

std::string absolute_text(const std::filesystem::path& p) { return std::filesystem::absolute(p).string(); }

// The layer of the base material's fluorophore `name`, null when the base has none.
nlohmann::json* find_layer(nlohmann::json& base, const std::string& name) {
  for (auto& l : base["fluorophores"])
    if (l.value("name", "") == name) return &l;
  return nullptr;
}

// The user's overrides of the preset's base material, validated against the user's own JSON
// pointer before they are merged: reflectance, concentrations (their names go into `given`),
// fluorescence_scale, textures and extra_fluorophores.
void apply_user_overrides(const JsonNode& n, nlohmann::json& base, std::set<std::string>& given) {
  if (auto r = n.find("reflectance")) {
    nlohmann::json v = r->raw();
    if (v.is_string()) v = absolute_text(r->existing_file());
    else if (v.is_object() && v.contains("file")) v["file"] = absolute_text(r->at("file").existing_file());
    base["reflectance"] = v;
  }
  if (auto cs = n.find("concentrations")) {
    for (const auto& k : cs->keys()) {
      given.insert(k);
      double c = cs->at(k).number(0.0, 1.0);
      if (auto* l = find_layer(base, k)) (*l)["concentration"] = c;
      else base["fluorophores"].push_back({{"name", k}, {"concentration", c}});
    }
  }
  if (auto s = n.find("fluorescence_scale")) {
    double f = s->number(0.0, 1e4);
    for (auto& l : base["fluorophores"]) l["concentration"] = l["concentration"].get<double>() * f;
  }
  if (auto ts = n.find("textures")) {
    for (const auto& k : ts->keys()) {
      JsonNode t = ts->at(k);
      nlohmann::json tex;
      if (t.is_object()) {
        t.check_keys({"file", "offset", "scale"});
        tex = {{"file", absolute_text(t.at("file").existing_file())}, {"offset", t.number_or("offset", 0.0)},
               {"scale", t.number_or("scale", 1.0)}};
      } else {
        tex = absolute_text(t.existing_file());
      }
      nlohmann::json* l = find_layer(base, k);
      if (!l) t.fail("the preset has no fluorophore \"" + k + "\" (set its concentration in \"concentrations\" first)");
      (*l)["texture"] = tex;
    }
  }
  if (auto extra = n.find("extra_fluorophores")) {
    for (size_t i = 0; i < extra->size(); ++i) {
      JsonNode l = extra->at(i);
      nlohmann::json layer = l.raw();
      // File names are the user's, relative to the user's file.
      for (const char* k : {"eem", "fluorophore"})
        if (l.has(k)) layer[k] = absolute_text(l.at(k).existing_file());
      if (auto t = l.find("texture")) {
        if (t->is_object()) layer["texture"]["file"] = absolute_text(t->at("file").existing_file());
        else layer["texture"] = absolute_text(t->existing_file());
      }
      base["fluorophores"].push_back(layer);
    }
  }
}

// A diagnosis report's corrections: its extra fluorophores join the layers before parsing
// (concentration fixed once the EEMs are on the grid, set_extra_shares). A tissue cause the
// material cannot render is refused.
TissueCorrections read_diagnosis(const JsonNode& d, nlohmann::json& base) {
  auto report_file = d.existing_file();
  JsonFile rep = JsonFile::load(report_file);
  TissueCorrections corr;
  try {
    corr = tissue_corrections_from_report(rep.doc());
  } catch (const InputError& e) {
    throw InputError(report_file.string(), e.field(), e.what());
  }
  if (!corr.unrendered_tissue_causes.empty())
    throw InputError(report_file.string(), "/causes",
                     "cause \"" + corr.unrendered_tissue_causes[0] +
                         "\" changes the tissue's emission in a way the tissue material has no parameter for; it would be "
                         "left out of the image (remove it from the report to render the rest)");
  // A fluorophore the preset or the user already has keeps its layer; its concentration is set
  // from the reported share unless "concentrations" names it.
  for (auto& x : corr.extra_fluorophores)
    if (!find_layer(base, x.name)) base["fluorophores"].push_back({{"name", x.name}, {"concentration", 0.0}});
  return corr;
}

// Broadens this material's own copies of its EEMs (other materials keep the library's).
void broaden_own_eems(Material& out, MaterialContext& ctx, double fwhm_nm) {
  TissueCorrections broaden_only;
  broaden_only.emission_broadening_fwhm_nm = fwhm_nm;
  for (auto& f : out.fluorophores) {
    ctx.eems->push_back(apply_tissue_corrections((*ctx.eems)[f.eem], broaden_only));
    f.eem = static_cast<int>(ctx.eems->size()) - 1;
  }
}

// Blood under the surface: the transmittance out, and in along the longer excitation path.
void add_blood(Material& out, const BloodAbsorber& blood, const MaterialContext& ctx) {
  out.layer_out = blood_transmittance(blood, ctx.grid);
  BloodAbsorber in = blood;
  in.oxy_uM_cm *= blood.excitation_path_factor;
  in.deoxy_uM_cm *= blood.excitation_path_factor;
  out.layer_in = blood_transmittance(in, ctx.grid);
}

}  // namespace

Material parse_tissue(const JsonNode& n, MaterialContext& ctx, const std::string& forced_preset) {
  n.check_keys({"type", "preset", "reflectance", "concentrations", "fluorescence_scale", "textures", "extra_fluorophores",
                "coating", "blood", "emission_broadening_fwhm_nm", "diagnosis"});
  auto file = preset_file(n, forced_preset);
  JsonFile pf = JsonFile::load(file);
  nlohmann::json mat = pf.root().at("material").raw();  // a copy we edit
  nlohmann::json& base = mat["base"];
  // Paths inside the preset are relative to the preset; rewrite them so the edited copy can live anywhere.
  if (base["reflectance"].is_object() && base["reflectance"].contains("file"))
    base["reflectance"]["file"] = absolute_text(file.parent_path() / base["reflectance"]["file"].get<std::string>());
  std::set<std::string> given;  // fluorophores the user set
  apply_user_overrides(n, base, given);
  TissueCorrections corr;
  if (auto d = n.find("diagnosis")) corr = read_diagnosis(*d, base);
  if (auto w = n.find("emission_broadening_fwhm_nm")) corr.emission_broadening_fwhm_nm = w->number(0.0, 500.0);
  // The coating last: dropping it replaces `mat` by the base, which `base` refers into.
  if (auto c = n.find("coating")) {
    if (c->raw().is_boolean() && !c->boolean()) {
      nlohmann::json b = base;
      mat = std::move(b);
    } else {
      c->check_keys({"ior", "roughness"});
      mat["ior"] = c->number_or("ior", mat.value("ior", 1.33), 1.0, 3.0);
      mat["roughness"] = c->number_or("roughness", mat.value("roughness", 0.2), 0.001, 1.0);
    }
  }
  // Parse the merged material; errors in it name the preset file and the merged pointer.
  JsonFile merged = JsonFile::from(mat, file.string() + " (preset as modified by " + n.file() + " " + n.path() + ")");
  JsonNode m = merged.root();
  std::string type = m.at("type").string();
  Material out = type == "coated" ? parse_coated(m, ctx) : type == "fluorescent" ? parse_fluorescent(m, ctx) : parse_lambertian(m, ctx);
  if (corr.emission_broadening_fwhm_nm > 0) broaden_own_eems(out, ctx, corr.emission_broadening_fwhm_nm);
  if (!corr.extra_fluorophores.empty()) set_extra_shares(out, corr, ctx, given);
  std::optional<BloodAbsorber> blood = corr.blood;
  if (auto b = n.find("blood")) blood = parse_blood(*b);
  if (blood) add_blood(out, *blood, ctx);
  return out;
}

}  // namespace ofl
