// One design point of a sweep, start to finish: edit the documents (rig_generators.h), load the
// scene, render it (to the noise target when one is set), run the camera, split the signal, build
// the ROI masks and compute every metric (sweep_metrics.h); plus what the report draws (each ROI's
// cells in the (r, g) plane, the fluorophore reference lines for this point's LED and camera, a
// thumbnail). The result is one JSON object, self-contained, so it can be written as one file or
// sent over MPI as one message.
//
// Points are content-addressed: the key is a hash of everything that decides the point's result
// (the base files and their text, this point's parameter values and edits, render, camera and
// metric settings), not of its position in the design. A finished result therefore stays valid
// when the design grows or is reordered, and can never be stored twice.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/camera_description.h"
#include "renderer/scene/scene.h"
#include "renderer/image/texture.h"
#include "renderer/sweep/design/rig_generators.h"
#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/design/sweep_spec.h"

namespace ofl {

// 16 hex digits (FNV-1a 64 of the point's canonical description).
std::string point_key(const SweepSpec& spec, const DesignPoint& point);
// The same keys for many points of one sweep: what every point shares (the sweep's settings, the
// scene and camera files' text, hashed once per file) is computed once.
class PointKeys {
 public:
  explicit PointKeys(const SweepSpec& spec);
  std::string key(const DesignPoint& point);

 private:
  struct Frame {
    uint64_t prefix_hash;  // of the identity's text before the parameters
    std::string suffix;    // the text after them
  };
  const SweepSpec& spec_;
  nlohmann::json shared_;                                           // render, camera_run, rois, metrics
  std::map<std::string, std::pair<std::string, std::string>> files_;  // path -> (canonical name, text hash)
  std::map<std::string, Frame> frames_;                             // per pair of base files
};
nlohmann::json point_identity(const SweepSpec& spec, const DesignPoint& point);  // what the key hashes

class RenderCache;

struct PointRunContext {
  const RenderCache* render_cache = nullptr;  // renders shared by points with the same scene (none: render every point)
  std::map<std::string, Texture> textures;  // ROI textures by path, loaded once per run
  int rank = 0;                             // MPI rank (0 without MPI), recorded in the result
  bool progress = false;                    // the renderer's progress bar
};

struct PointOutcome {
  nlohmann::ordered_json result;  // empty when interrupted (keys in a readable order)
  bool interrupted = false;  // SIGINT arrived during the render: nothing to save
};

PointOutcome evaluate_point(const SweepSpec& spec, const DesignPoint& point, PointRunContext& ctx);

// The point's scene and camera, loaded from its edited documents. A value the loaders reject is an
// InputError naming the sweep file and the parameter (or "/parameters"), with the point and the
// loader's own file and field in the message. The runner loads every point up front, so a bad
// value fails before the first render.
struct LoadedPoint {
  Scene scene;
  CameraDescription camera;
  PointDocuments docs;                            // the edited documents the scene and camera came from
  SceneOverrides overrides;                       // the sweep's render settings
  std::set<std::filesystem::path> scene_inputs;   // every file the scene loader read (part of the render key)
};
LoadedPoint load_point(const SweepSpec& spec, const DesignPoint& point);

// Standard base64 (RFC 4648), for thumbnails inside the result JSON.
std::string base64_encode(const std::string& bytes);
std::string base64_decode(const std::string& text);  // ignores anything that is not base64

}  // namespace ofl
