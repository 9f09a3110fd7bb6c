// The sweep's render cache (renderer/sweep/store/render_cache.h): a sweep whose points differ only
// in a camera field renders once and gives, bit for bit, the metrics of a sweep that renders every
// point; a changed byte of a spectrum CSV the scene names, or another spp, is another render; the
// scene loader's inputs are recorded the same way on every load; a cached render reads back exactly.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

#include "renderer/core/files/file_dependencies.h"
#include "renderer/scene/scene.h"
#include "renderer/sweep/design/sweep_design.h"
#include "renderer/sweep/design/sweep_spec.h"
#include "renderer/sweep/store/render_cache.h"
#include "renderer/sweep/sweep_point.h"
#include "renderer/sweep/sweep_runner.h"

using namespace ofl;

namespace {

const std::filesystem::path kSource = OFL_SOURCE_DIR;

std::filesystem::path fresh(const std::string& name) { return ofl::test::fresh_dir("sweep_cache_" + name); }
using ofl::test::slurp;

void write(const std::filesystem::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// Files in `dir` with this extension (hidden temporaries included, so a leftover one shows).
std::vector<std::filesystem::path> files_with(const std::filesystem::path& dir, const std::string& ext) {
  std::vector<std::filesystem::path> v;
  std::error_code ec;
  for (auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ext) v.push_back(e.path());
  return v;
}

size_t entries(const std::filesystem::path& dir) {
  size_t n = 0;
  std::error_code ec;
  for (auto it = std::filesystem::directory_iterator(dir, ec); !ec && it != std::filesystem::directory_iterator(); ++it) ++n;
  return n;
}

// Every point result stored in a sweep folder (points of other designs too).
std::vector<nlohmann::json> stored_points(const std::filesystem::path& out) {
  std::vector<nlohmann::json> v;
  for (auto& p : files_with(out / "points", ".json"))
    if (p.filename().string()[0] != '.') v.push_back(nlohmann::json::parse(slurp(p)));
  return v;
}

// The same, by design index (one design per folder).
std::map<int, nlohmann::json> points(const std::filesystem::path& out) {
  std::map<int, nlohmann::json> m;
  for (auto& j : stored_points(out)) m[j["index"].get<int>()] = j;
  return m;
}

int run_cli(const std::string& args, const std::filesystem::path& dir, const std::string& tag) {
  std::string cmd = std::string(OFL_BINARY) + " sweep " + args + " > " + (dir / (tag + ".out")).string() + " 2> " +
                    (dir / (tag + ".err")).string();
  int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

SweepRunSummary run_in_process(const std::filesystem::path& sweep_file, const std::filesystem::path& out,
                               std::optional<int> spp = std::nullopt) {
  SweepSpec spec = load_sweep_spec(sweep_file);
  if (spp) spec.render.spp = spp;
  SweepRunOptions o;
  o.out_dir = out;
  return run_sweep(spec, o);
}

// A one-material scene whose reflectance is a CSV beside it: the file the key must notice.
void write_patch_scene(const std::filesystem::path& dir) {
  write(dir / "reflectance.csv", "wavelength_nm,value\n350,0.20\n500,0.35\n780,0.60\n");
  write(dir / "scene.json", R"({
  "format": "oralfluor-scene", "version": 1,
  "integrator": {"spp": 2, "max_depth": 2, "seed": 7,
                 "wavelengths": {"min_nm": 350, "max_nm": 780, "step_nm": 10}},
  "camera": {"position": [0, 0, 0.3], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 18, "resolution": [24, 18]},
  "materials": {"tongue": {"type": "fluorescent", "reflectance": "reflectance.csv",
                           "fluorophores": [{"name": "FAD", "concentration": 0.05}]}},
  "geometry": [{"type": "quad", "center": [0, 0, 0], "u": [0.2, 0, 0], "v": [0, 0.2, 0], "material": "tongue"}],
  "lights": [{"spd": {"type": "gaussian", "peak_nm": 405, "fwhm_nm": 15}, "radiant_intensity_W_sr": 0.1,
              "profile": {"half_angle_deg": 60}, "position": [0, 0, 0.1], "target": [0, 0, 0]}]
})");
  nlohmann::json sweep = {{"format", "oralfluor-sweep"},
                          {"version", 1},
                          {"name", "patch"},
                          {"scene", "scene.json"},
                          {"camera", (kSource / "scenes/cameras/oraleye.json").string()},
                          {"render", {{"width", 24}, {"spp", 2}}},
                          {"parameters", {{{"name", "lp_edge"}, {"camera", "/filters/0/edge_nm"}, {"values", {470}}}}}};
  write(dir / "sweep.json", sweep.dump(1));
}

}  // namespace

// (a) Four long-pass edges, one scene: one render, three points read it, and every metric equals
// that of the same sweep rendering each point (--no-render-cache) bit for bit.
TEST(SweepCache, CameraOnlySweepRendersOnceWithTheSameMetrics) {
  auto dir = fresh("edge");
  nlohmann::json sweep = {
      {"format", "oralfluor-sweep"},
      {"version", 1},
      {"name", "edge"},
      {"scene", (kSource / "scenes/oraleye_385.json").string()},
      {"camera", (kSource / "scenes/cameras/oraleye.json").string()},
      {"render", {{"width", 24}, {"spp", 2}, {"max_depth", 3}}},
      {"camera_run", {{"noise", true}, {"seed", 3}}},
      {"parameters", {{{"name", "lp_edge"}, {"camera", "/filters/0/edge_nm"}, {"values", {455, 470, 485, 500}}}}}};
  write(dir / "edge.json", sweep.dump(1));

  ASSERT_EQ(run_cli((dir / "edge.json").string() + " -o " + (dir / "cached").string(), dir, "cached"), 0)
      << slurp(dir / "cached.err");
  auto renders = files_with(dir / "cached" / "renders", ".exr");
  ASSERT_EQ(renders.size(), 1u) << "one scene, one render";
  EXPECT_EQ(files_with(dir / "cached" / "renders", ".json").size(), 1u);
  EXPECT_EQ(entries(dir / "cached" / "renders"), 2u) << "the EXR and its statistics, no temporary left";
  auto cached = points(dir / "cached");
  ASSERT_EQ(cached.size(), 4u);
  int from_cache = 0;
  for (auto& [i, p] : cached) {
    from_cache += p["render_cached"].get<bool>();
    EXPECT_EQ(p["render_key"], cached[0]["render_key"]);
  }
  EXPECT_EQ(from_cache, 3);
  EXPECT_EQ(renders[0].stem().string(), cached[0]["render_key"].get<std::string>());

  ASSERT_EQ(run_cli((dir / "edge.json").string() + " -o " + (dir / "fresh").string() + " --no-render-cache", dir, "fresh"), 0)
      << slurp(dir / "fresh.err");
  EXPECT_FALSE(std::filesystem::exists(dir / "fresh" / "renders")) << "no cache: nothing stored";
  auto rendered = points(dir / "fresh");
  ASSERT_EQ(rendered.size(), 4u);
  std::set<std::string> distinct;
  for (auto& [i, p] : rendered) {
    EXPECT_FALSE(p["render_cached"].get<bool>());
    // The cache setting is not part of a point's identity: the same points, the same keys.
    EXPECT_EQ(p["key"], cached[i]["key"]);
    EXPECT_EQ(p["render_key"], cached[i]["render_key"]) << "the key does not depend on the cache being used";
    // JSON numbers are written to round-trip, so equal text means equal doubles.
    EXPECT_EQ(p["metrics"].dump(), cached[i]["metrics"].dump()) << "point " << i;
    EXPECT_EQ(p["scatter"].dump(), cached[i]["scatter"].dump()) << "point " << i;
    distinct.insert(p["metrics"].dump());
  }
  // The edge does change what the camera records: a cache that froze the camera would fail here.
  EXPECT_EQ(distinct.size(), 4u);
  std::filesystem::remove_all(dir);
}

// (b) One byte of the reflectance CSV is another scene: a new key and a new render; the same
// bytes, even after the points are deleted, are read from the cache.
TEST(SweepCache, ChangedByteOfAReferencedSpectrumIsANewRender) {
  auto dir = fresh("csv");
  write_patch_scene(dir);
  auto out = dir / "out";
  run_in_process(dir / "sweep.json", out);
  auto first = points(out);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_FALSE(first[0]["render_cached"].get<bool>());
  const std::string key = first[0]["render_key"];

  // The point keys do not hash the CSV, so remove the finished point to compute it again.
  std::filesystem::remove_all(out / "points");
  run_in_process(dir / "sweep.json", out);
  auto again = points(out);
  EXPECT_TRUE(again[0]["render_cached"].get<bool>()) << "same bytes: the stored render";
  EXPECT_EQ(again[0]["render_key"], key);
  EXPECT_EQ(again[0]["metrics"].dump(), first[0]["metrics"].dump());

  std::string csv = slurp(dir / "reflectance.csv");
  auto at = csv.find("0.35");
  ASSERT_NE(at, std::string::npos);
  csv[at + 3] = '6';  // 0.35 -> 0.36: one byte
  write(dir / "reflectance.csv", csv);
  std::filesystem::remove_all(out / "points");
  run_in_process(dir / "sweep.json", out);
  auto changed = points(out);
  EXPECT_FALSE(changed[0]["render_cached"].get<bool>()) << "a changed input is rendered again";
  EXPECT_NE(changed[0]["render_key"], key);
  EXPECT_NE(changed[0]["metrics"].dump(), first[0]["metrics"].dump());
  EXPECT_EQ(files_with(out / "renders", ".exr").size(), 2u);
  std::filesystem::remove_all(dir);
}

// (c) Another spp is another render (and another point).
TEST(SweepCache, OtherSppIsANewRender) {
  auto dir = fresh("spp");
  write_patch_scene(dir);
  auto out = dir / "out";
  run_in_process(dir / "sweep.json", out);
  auto a = points(out);
  ASSERT_EQ(a.size(), 1u);
  SweepRunSummary s = run_in_process(dir / "sweep.json", out, 3);
  EXPECT_EQ(s.computed, 1);
  auto b = stored_points(out);
  ASSERT_EQ(b.size(), 2u) << "both points' files: the spp is part of the point key";
  nlohmann::json spp3;
  for (auto& p : b)
    if (p["key"] != a[0]["key"]) spp3 = p;
  ASSERT_FALSE(spp3.is_null());
  EXPECT_FALSE(spp3["render_cached"].get<bool>());
  EXPECT_NE(spp3["render_key"], a[0]["render_key"]);
  EXPECT_EQ(spp3["render"]["spp"], 3);
  EXPECT_EQ(files_with(out / "renders", ".exr").size(), 2u);
  std::filesystem::remove_all(dir);
}

// The inputs the key hashes are found the same way on every load (else points of one scene would
// not share a render), and include the meshes, textures, tissue presets and spectra it names.
TEST(SweepCache, SceneInputsAreRecordedCompletelyAndAlike) {
  auto load = [] {
    FileDependencyRecorder r;
    SceneOverrides ov;
    ov.width = 16;
    load_scene(kSource / "scenes/oraleye_385.json", ov);
    return r.files();
  };
  auto a = load(), b = load();
  EXPECT_EQ(a, b);
  std::set<std::string> names;
  for (auto& f : a) names.insert(f.filename().string());
  for (const char* n : {"tongue.glb", "mouth.glb", "teeth.glb", "tongue_porphyrin.png", "oraleye_385nm_led.csv",
                        "tongue.json", "oraleye.json"})
    EXPECT_TRUE(names.count(n)) << n << " is an input of the demo scene";
  // Nothing is recorded outside a recorder.
  FileDependencyRecorder outer;
  { FileDependencyRecorder inner; }
  EXPECT_TRUE(outer.files().empty());
}

// The spectral image, its fluorescence layer, AOV planes, exact band centres and the render's
// statistics come back from the cache as they went in; a damaged entry is not a render.
TEST(SweepCache, StoredRenderReadsBackExactly) {
  auto dir = fresh("roundtrip");
  SpectralImage img;
  img.resize(5, 3, {362.5, 400.0 + 1.0 / 3.0, 512.125});
  for (size_t i = 0; i < img.data.size(); ++i) img.data[i] = float(std::sin(double(i)) * 1e-3 + 2e-3);
  img.fluorescence.resize(img.data.size());
  for (size_t i = 0; i < img.data.size(); ++i) img.fluorescence[i] = img.data[i] * 0.25f;
  img.aovs["aov.material"] = std::vector<float>(15, 2.0f);
  img.aovs["aov.u"] = std::vector<float>(15, 0.125f);
  img.attributes["spp"] = "2";
  RenderStats st;
  st.spp_done = 2;
  st.seconds = 1.5;
  st.camera_samples = 30;
  st.relative_noise = 0.0625;
  RenderCache cache(dir);
  const std::string key = "0123456789abcdef0123456789abcdef";
  EXPECT_FALSE(cache.load(key).has_value());
  cache.save(key, {{"what", "test"}}, img, st);
  auto c = cache.load(key);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->image.width, 5);
  EXPECT_EQ(c->image.height, 3);
  EXPECT_EQ(c->image.band_nm, img.band_nm);
  EXPECT_EQ(c->image.data, img.data);
  EXPECT_EQ(c->image.fluorescence, img.fluorescence);
  EXPECT_EQ(c->image.aovs, img.aovs);
  EXPECT_EQ(c->image.attributes, img.attributes);
  EXPECT_EQ(c->stats.spp_done, 2);
  EXPECT_EQ(c->stats.seconds, 1.5);
  EXPECT_EQ(c->stats.camera_samples, 30u);
  EXPECT_EQ(c->stats.relative_noise, 0.0625);
  EXPECT_EQ(cache.keys(), std::vector<std::string>{key});
  // A statistics file that names another key, or an EXR that is not there, is no entry.
  auto stats = nlohmann::json::parse(slurp(cache.json_file(key)));
  stats["key"] = "ffffffffffffffffffffffffffffffff";
  write(cache.json_file(key), stats.dump());
  EXPECT_FALSE(cache.load(key).has_value());
  cache.save(key, {{"what", "test"}}, img, st);
  std::filesystem::remove(cache.exr_file(key));
  EXPECT_FALSE(cache.load(key).has_value());
  std::filesystem::remove_all(dir);
}

// The key: stable for equal inputs, and changed by the scene document, the overrides and the
// replicate; "render": {"cache": false} in a sweep file is read and does not change point keys.
TEST(SweepCache, KeyFollowsDocumentOverridesAndReplicate) {
  auto dir = fresh("key");
  write_patch_scene(dir);
  std::set<std::filesystem::path> files = {dir / "reflectance.csv"};
  nlohmann::json doc = nlohmann::json::parse(slurp(dir / "scene.json"));
  SceneOverrides ov;
  ov.spp = 2;
  const std::string k = render_key(render_identity(doc, dir, files, ov));
  EXPECT_EQ(k.size(), 32u);
  EXPECT_EQ(render_key(render_identity(doc, dir, files, ov)), k);
  EXPECT_NE(render_key(render_identity(doc, dir, files, ov, 1)), k);
  SceneOverrides ov2 = ov;
  ov2.width = 24;
  EXPECT_NE(render_key(render_identity(doc, dir, files, ov2)), k);
  nlohmann::json doc2 = doc;
  doc2["lights"][0]["radiant_intensity_W_sr"] = 0.2;
  EXPECT_NE(render_key(render_identity(doc2, dir, files, ov)), k);

  nlohmann::json sweep = nlohmann::json::parse(slurp(dir / "sweep.json"));
  SweepSpec on = load_sweep_spec(dir / "sweep.json");
  sweep["render"]["cache"] = false;
  write(dir / "nocache.json", sweep.dump());
  SweepSpec off = load_sweep_spec(dir / "nocache.json");
  EXPECT_TRUE(on.render.cache);
  EXPECT_FALSE(off.render.cache);
  EXPECT_EQ(off.to_json()["render"]["cache"], false);
  auto pa = make_design(on), pb = make_design(off);
  ASSERT_EQ(pa.size(), 1u);
  ASSERT_EQ(pb.size(), 1u);
  EXPECT_EQ(point_key(on, pa[0]), point_key(off, pb[0])) << "where a render comes from does not change a point";
  std::filesystem::remove_all(dir);
}
