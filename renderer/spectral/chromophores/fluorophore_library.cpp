#include "renderer/spectral/chromophores/fluorophore_library.h"

#include <algorithm>

#include "renderer/core/files/asset_path.h"
#include "renderer/core/errors/error.h"
#include "renderer/core/files/json_node.h"

namespace ofl {

std::vector<FluorophoreEntry> fluorophore_library() {
  std::vector<FluorophoreEntry> out;
  auto dir = asset_root() / "fluorophores";
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(dir, ec)) {
    if (e.path().extension() != ".json") continue;
    JsonFile f = JsonFile::load(e.path());
    JsonNode r = f.root();
    out.push_back({r.at("name").string(), r.string_or("description", ""), r.string_or("citation", ""), e.path()});
  }
  std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.name < b.name; });
  return out;
}

double max_photon_albedo(const Eem& e) {
  double best = 0;
  for (size_t c = 0; c < e.ex_nm.size(); ++c) {
    double s = 0;
    for (size_t r = 1; r < e.em_nm.size(); ++r) {
      if (e.em_nm[r - 1] <= e.ex_nm[c]) continue;
      s += 0.5 * (e.at(r - 1, c) + e.at(r, c)) * (e.em_nm[r] - e.em_nm[r - 1]);
    }
    best = std::max(best, s);
  }
  return best;
}

static GridEem load_sidecar(const std::filesystem::path& file, const WavelengthGrid& grid) {
  JsonFile f = JsonFile::load(file);
  JsonNode r = f.root();
  r.check_keys({"name", "description", "eem", "excitation", "emission", "normalise", "citation", "provenance", "licence", "units"});
  bool normalise = r.boolean_or("normalise", true);
  GridEem g;
  if (auto e = r.find("eem")) {
    Eem raw = read_eem_csv(e->existing_file());
    g = resample(raw, grid);
    g.source = e->existing_file().string();
    if (normalise) {
      double m = max_photon_albedo(raw);
      if (!(m > 0)) e->fail("EEM is zero everywhere above the diagonal");
      g.scale(1.0 / m);
    }
  } else {
    SpectrumCsvOptions o;
    auto xs = table_spectrum(read_spectrum_csv(r.at("excitation").existing_file(), o), "excitation");
    auto es = table_spectrum(read_spectrum_csv(r.at("emission").existing_file(), o), "emission");
    g = eem_from_pair(xs, es, grid);
    if (normalise) {
      // Peak excitation 1 and unit-area emission give albedo 1 at the peak before the Stokes mask;
      // normalising after the mask keeps the definition "largest photon albedo = 1".
      auto a = g.photon_albedo();
      double m = *std::max_element(a.begin(), a.end());
      if (!(m > 0)) r.fail("excitation and emission do not overlap the wavelength grid");
      g.scale(1.0 / m);
    }
    g.source = file.string();
  }
  return g;
}

GridEem load_fluorophore(const std::string& what, const WavelengthGrid& grid, const std::filesystem::path& base_dir,
                         bool normalise_csv) {
  std::filesystem::path p = what;
  bool is_file = p.has_extension() && (p.extension() == ".json" || p.extension() == ".csv");
  if (!is_file) {
    auto side = asset_root() / "fluorophores" / (what + ".json");
    std::error_code ec;
    if (!std::filesystem::exists(side, ec)) {
      std::string names;
      for (auto& e : fluorophore_library()) names += (names.empty() ? "" : ", ") + e.name;
      throw InputError("", "fluorophore \"" + what + "\"", "not in the library (have: " + names + ")");
    }
    return load_sidecar(side, grid);
  }
  if (p.is_relative() && !base_dir.empty()) p = base_dir / p;
  if (p.extension() == ".json") return load_sidecar(p, grid);
  Eem raw = read_eem_csv(p);
  GridEem g = resample(raw, grid);
  g.source = p.string();
  if (normalise_csv) {
    double m = max_photon_albedo(raw);
    if (!(m > 0)) throw InputError(p.string(), "", "EEM is zero everywhere above the diagonal");
    g.scale(1.0 / m);
  }
  return g;
}

}  // namespace ofl
