// Renders shared between sweep points: a content-addressed cache in <out>/renders/.
//
// Points that differ only in camera, filter or sensor fields render the same scene with the same
// settings and the same seed, hence (the renderer is bit-identical for any thread count) the same
// image. The cache key is a hash of what decides the render:
//  - the point's final scene document, as passed to load_scene (after the sweep's scene edits and
//    render settings),
//  - the bytes of every file the scene loader read for it (meshes and their buffers, spectra,
//    EEMs and fluorophore sidecars, textures, tissue presets: file_dependencies.h), each under its
//    path relative to the scene's folder, so a changed byte of a spectrum CSV means a new render,
//  - the overrides (spp, seed, width, height), the replicate (a second, independently seeded
//    render of the same scene) and kRenderCacheVersion.
// Each entry is <key>.exr (the spectral image with its fluorescence layer and AOV planes) and
// <key>.json (render statistics, exact band centres, the identity that was hashed). Both are
// written atomically (write_file_atomic: temporary, fsync, rename), the EXR first, so an entry
// counts only once its JSON exists. Shards or MPI ranks that compute the same key at once each
// rename a complete file over the name: the last writer wins, with identical content.
#pragma once
#include <filesystem>
#include <optional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "renderer/image/spectral_image.h"
#include "renderer/render/render_job.h"
#include "renderer/scene/scene.h"

namespace ofl {

// Bump when what a cached render holds changes (renderer output, EXR layout, identity fields), so
// that old entries are never read as current ones.
constexpr int kRenderCacheVersion = 1;

// What the key hashes. `files` are the scene loader's inputs (absolute paths); `scene_dir` is the
// folder relative paths in the document are resolved against.
nlohmann::json render_identity(const nlohmann::json& scene_doc, const std::filesystem::path& scene_dir,
                               const std::set<std::filesystem::path>& files, const SceneOverrides& overrides,
                               int replicate = 0);
// 32 hex digits (FNV-1a 128 of the identity's JSON text, keys sorted).
std::string render_key(const nlohmann::json& identity);
// FNV-1a 128 of a file's bytes, as 32 hex digits (throws InputError when it cannot be read).
std::string file_hash(const std::filesystem::path& file);

struct CachedRender {
  SpectralImage image;
  RenderStats stats;  // of the render as it was computed (spp, noise, seconds)
};

class RenderCache {
 public:
  // <out_dir>/renders, created unless `create` is false.
  explicit RenderCache(std::filesystem::path out_dir, bool create = true);
  const std::filesystem::path& dir() const { return dir_; }
  std::filesystem::path exr_file(const std::string& key) const { return dir_ / (key + ".exr"); }
  std::filesystem::path json_file(const std::string& key) const { return dir_ / (key + ".json"); }
  // The stored render when both files exist, the JSON names this key and format, and the EXR has
  // the recorded size and bands; nullopt otherwise (the caller renders again and overwrites). An
  // entry that exists but fails these checks is said in `*damaged` (when given).
  std::optional<CachedRender> load(const std::string& key, std::string* damaged = nullptr) const;
  void save(const std::string& key, const nlohmann::json& identity, const SpectralImage& image,
            const RenderStats& stats) const;
  std::vector<std::string> keys() const;  // every complete entry (its JSON exists)

 private:
  std::filesystem::path dir_;
};

}  // namespace ofl
