// The sweep description (`oralfluor sweep sweep.json`): a base scene and camera, the parameters to
// vary (any JSON pointer of the scene or camera, LED-ring generators, named variants), the design
// (full grid or Latin hypercube), render and camera settings, the named regions of interest and
// what the report shows. One plain struct, parsed with errors that name the sweep file and the
// JSON pointer of the field, and written back (to_json) into the output folder so a result can be
// traced to exactly what produced it. Format: docs/sweep-format.md.
#pragma once
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/core/files/json_node.h"

namespace ofl {

// Where a parameter's value goes.
enum class ParamKind {
  kScenePath,   // "scene": "/json/pointer" of the scene document
  kCameraPath,  // "camera": "/json/pointer" of the camera document
  kGenerator,   // "generator": a rig generator (rig_generators.h)
  kVariants,    // "variants": named sets of edits (controlled comparisons)
};

struct ParamRange {
  double min = 0, max = 1;
  int steps = 2;          // grid levels (evenly spaced, both ends included)
  bool log = false;       // "scale": "log": levels evenly spaced in log
  bool integer = false;   // values rounded to integers
};

// One named set of edits: pointer -> value, applied to the scene and the camera documents.
struct Variant {
  std::string label;
  std::vector<std::pair<std::string, nlohmann::json>> scene_edits, camera_edits;
};

struct SweepParameter {
  std::string name;              // column name in the results
  ParamKind kind = ParamKind::kScenePath;
  std::string pointer;           // kScenePath / kCameraPath
  std::string generator;         // kGenerator
  int light = 0;                 // generators: index into the scene's "lights"
  int filter = -1;               // camera_filter_edge: index into the camera's "filters" (-1: the first long-pass)
  double peak_nm = 0;            // led_fwhm: peak of the Gaussian line (0: keep the LED's own peak)
  std::vector<nlohmann::json> values;  // discrete levels ("values", or a range expanded for grids)
  std::optional<ParamRange> range;     // continuous range (Latin hypercube samples it continuously)
  std::vector<Variant> variants;       // kVariants (values then hold the labels)
  std::string where;             // JSON pointer of this parameter in the sweep file, for errors

  bool numeric() const;          // every level is a number (plots use a numeric axis)
  int levels() const { return static_cast<int>(values.size()); }
};

// Adds to `j` what a scene-path, camera-path or generator parameter changes ("scene"/"camera"
// pointer, or the generator with its light, filter and peak); variants are described by callers.
void describe_target(const SweepParameter& p, nlohmann::json& j);


// A texture looked up at the pixel's UV must lie strictly between `above` and `below`.
struct TextureCondition {
  std::filesystem::path file;  // resolved against the sweep file
  double above = -std::numeric_limits<double>::infinity();
  double below = std::numeric_limits<double>::infinity();
};

// A named region of interest: pixels that see `material` and meet every texture condition (e.g.
// lesion map > 0.5; or lesion map < 0.1 and porphyrin map < 0.05 for uniform tongue tissue).
struct RoiSpec {
  std::string name, material;
  std::vector<TextureCondition> textures;
};

struct RenderSettings {
  std::optional<int> width, height, spp, max_depth;
  std::optional<uint64_t> seed;
  std::optional<double> noise_target;  // > 0: stop at this relative noise; spp is then the maximum
  // Film bands {"min_nm", "max_nm", "step_nm"}: must reach down into the LED's band for the
  // leaked excitation to be simulated at all (scenes often start their bands at 400 nm).
  std::optional<nlohmann::json> output_bands;
  // 2: render every point twice with different seeds and average; the difference of the two gives
  // the Monte Carlo noise of the chromaticity metrics (sweep_metrics.h "_mc", "_light").
  int replicates = 1;
  // "cache": false: render every point, even when another point already rendered the same scene
  // with the same settings (render_cache.h). Never part of a point's key: the results are the same.
  bool cache = true;
};

struct CameraSettings {
  std::optional<bool> noise;
  std::optional<uint64_t> seed;
};

// The most points a design may have (a grid's product of levels, a Latin hypercube's points): what
// a run's bookkeeping handles in seconds - keys, the up-front checks, the manifest, the dry run and
// the report, which shows every point in its CSV, JSON and plots and the first kReportPointsShown
// with thumbnails and scatter plots (benchmarks/results.d/62_sweep_size.md measures it).
constexpr int kMaxSweepPoints = 100000;

struct DesignSpec {
  enum class Type { kGrid, kLatinHypercube } type = Type::kGrid;
  int points = 0;      // Latin hypercube: number of points
  uint64_t seed = 1;   // Latin hypercube: permutation and jitter seed
};

struct MetricSettings {
  // A transport-grid wavelength belongs to the LED's emission band when the summed, filtered LED
  // spectrum there is at least this fraction of its peak (sweep_metrics.h: leaked excitation).
  double led_band_threshold = 1e-3;
  std::string lesion_roi, healthy_roi;  // lesion contrast between these ROIs (both empty: none)
  int scatter_cells = 300;              // cells per ROI kept for the report's scatter plots
};

struct ReportSettings {
  std::vector<std::string> metrics;     // metric names plotted against every parameter (per ROI)
  int thumbnail_width = 120;
  bool scatter_noise_free = false;      // "scatter": "raw" (default) or "noise_free" cells in the scatter plots
  std::vector<std::string> scatter_rois;  // ROIs drawn in the scatter plots (empty: all)
};

struct SweepSpec {
  std::string file;                     // the sweep file as given
  std::string name, description;
  std::filesystem::path scene, camera;  // resolved against the sweep file
  RenderSettings render;
  CameraSettings camera_run;
  DesignSpec design;
  std::vector<SweepParameter> parameters;
  std::vector<RoiSpec> rois;
  MetricSettings metrics;
  ReportSettings report;

  const RoiSpec* roi(const std::string& name) const;
  // Canonical form: everything that decides the results (written as sweep.json in the output).
  nlohmann::json to_json() const;
};

SweepSpec parse_sweep_spec(const JsonFile& file);
SweepSpec load_sweep_spec(const std::filesystem::path& file);

// The default metrics plotted against every parameter when "report": {"metrics"} is absent.
const std::vector<std::string>& default_report_metrics();

}  // namespace ofl
