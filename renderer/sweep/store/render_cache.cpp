#include "renderer/sweep/store/render_cache.h"

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/hash.h"
#include "renderer/image/spectral_exr.h"
#include "renderer/sweep/store/sweep_store.h"

namespace ofl {
namespace {

nlohmann::json opt_json(const auto& o) { return o ? nlohmann::json(*o) : nlohmann::json(nullptr); }

}  // namespace

std::string file_hash(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot read (an input of the scene)");
  Fnv128 f;
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    f.add(buf.data(), size_t(in.gcount()));
  }
  return f.hex();
}

nlohmann::json render_identity(const nlohmann::json& scene_doc, const std::filesystem::path& scene_dir,
                               const std::set<std::filesystem::path>& files, const SceneOverrides& ov, int replicate) {
  std::error_code ec;
  std::filesystem::path base = std::filesystem::absolute(scene_dir.empty() ? "." : scene_dir, ec).lexically_normal();
  // Each input under its path relative to the scene's folder: the association of bytes with names
  // matters (two swapped textures are another scene), the folder the scene sits in does not.
  nlohmann::json inputs = nlohmann::json::object();
  for (const auto& f : files) inputs[f.lexically_relative(base).generic_string()] = file_hash(f);
  nlohmann::json id = {{"render_cache_version", kRenderCacheVersion},
                       {"scene", scene_doc},
                       {"files", inputs},
                       {"overrides", {{"spp", opt_json(ov.spp)},
                                      {"seed", opt_json(ov.seed)},
                                      {"width", opt_json(ov.width)},
                                      {"height", opt_json(ov.height)}}}};
  if (replicate != 0) id["replicate"] = replicate;
  return id;
}

std::string render_key(const nlohmann::json& identity) {
  const std::string text = identity.dump();  // nlohmann::json keeps object keys sorted
  Fnv128 f;
  f.add(text.data(), text.size());
  return f.hex();
}

RenderCache::RenderCache(std::filesystem::path out_dir, bool create) : dir_(std::move(out_dir) / "renders") {
  if (!create) return;
  std::error_code ec;
  std::filesystem::create_directories(dir_, ec);
  if (!std::filesystem::is_directory(dir_, ec)) throw InputError(dir_.string(), "", "cannot create the renders folder");
  remove_stale_temporaries(dir_);
}

std::optional<CachedRender> RenderCache::load(const std::string& key, std::string* damaged) const {
  std::ifstream in(json_file(key), std::ios::binary);
  if (!in) return std::nullopt;
  auto bad = [&](const std::string& why) -> std::optional<CachedRender> {
    if (damaged) *damaged = json_file(key).string() + ": cached render ignored (" + why + "); rendering it again";
    return std::nullopt;
  };
  try {
    nlohmann::json j = nlohmann::json::parse(in);
    if (j.value("format", std::string()) != "oralfluor-render-cache" || j.value("version", 0) != kRenderCacheVersion ||
        j.value("key", std::string()) != key)
      return bad("another format, version or key");
    CachedRender c;
    c.image = read_spectral_exr(exr_file(key));
    const auto& bands = j.at("band_nm");
    if (c.image.width != j.at("width").get<int>() || c.image.height != j.at("height").get<int>() ||
        c.image.bands() != int(bands.size()))
      return bad("the EXR's size or bands differ from the entry's");
    // The EXR's channel names carry 6 decimals; the exact centres come from the JSON.
    c.image.band_nm = bands.get<std::vector<double>>();
    // Header strings the EXR layout adds, not the renderer: the image is the one the render made.
    c.image.attributes.erase("spectralLayoutVersion");
    c.image.attributes.erase("emissiveUnits");
    const auto& s = j.at("stats");
    c.stats.seconds = s.at("seconds").get<double>();
    c.stats.build_seconds = s.at("build_seconds").get<double>();
    c.stats.spp_done = s.at("spp_done").get<int>();
    c.stats.camera_samples = s.at("camera_samples").get<uint64_t>();
    c.stats.relative_noise = s.at("relative_noise").get<double>();
    return c;
  } catch (const InputError& e) {
    return bad(e.describe());  // the EXR: missing, cut short, not an EXR
  } catch (const std::exception& e) {
    return bad(std::string("unreadable: ") + e.what());  // the JSON
  }
}

void RenderCache::save(const std::string& key, const nlohmann::json& identity, const SpectralImage& image,
                       const RenderStats& stats) const {
  write_file_atomic(exr_file(key), spectral_exr_bytes(image));
  nlohmann::ordered_json j;
  j["format"] = "oralfluor-render-cache";
  j["version"] = kRenderCacheVersion;
  j["key"] = key;
  j["width"] = image.width;
  j["height"] = image.height;
  j["band_nm"] = image.band_nm;
  j["stats"] = {{"seconds", stats.seconds},
                {"build_seconds", stats.build_seconds},
                {"spp_done", stats.spp_done},
                {"camera_samples", stats.camera_samples},
                {"relative_noise", stats.relative_noise}};
  j["identity"] = identity;
  write_file_atomic(json_file(key), j.dump(1) + "\n");
}

std::vector<std::string> RenderCache::keys() const {
  std::vector<std::string> k;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(dir_, ec)) {
    std::string n = e.path().filename().string();
    if (n.size() > 5 && n[0] != '.' && e.path().extension() == ".json") k.push_back(e.path().stem().string());
  }
  std::sort(k.begin(), k.end());
  return k;
}

}  // namespace ofl
