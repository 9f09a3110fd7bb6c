// `oralfluor mesh mouth`: writes the procedural mouth (lips, cheeks, palate, floor, skin and an
// optional procedural tongue) as glTF binary. Parameters come from the defaults, then a JSON
// file (--params), then one flag per parameter (--opening-m 0.035 ...), later ones winning.
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "renderer/cli/assets/cmd_mesh_parts.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/mesh/files/gltf_writer.h"
#include "renderer/mesh/geometry/mesh_measure.h"
#include "renderer/mesh/mouth/mouth_generator.h"
#include "renderer/mesh/mouth/mouth_params.h"

namespace ofl {

void register_mouth_command(CLI::App& mesh) {
  struct Opts {
    std::string out, params;
    bool no_tongue = false, print = false, json = false;
    int segments = 0;
    std::vector<double> values;
  };
  auto o = std::make_shared<Opts>();
  const auto& table = mouth_param_table();
  o->values.assign(table.size(), std::numeric_limits<double>::quiet_NaN());
  auto* cmd = mesh.add_subcommand("mouth", "write the procedural mouth as glTF binary (parameters: --print-params)");
  cmd->add_option("-o,--output", o->out, "output .glb");
  cmd->add_option("--params", o->params, "JSON file of mouth parameters (see --print-params)");
  cmd->add_flag("--no-tongue", o->no_tongue, "leave out the procedural tongue");
  cmd->add_option("--segments", o->segments, "vertices around each ring (multiple of 8)");
  cmd->add_flag("--print-params", o->print, "print the parameters (defaults + file + flags) as JSON and exit");
  cmd->add_flag("--json", o->json, "print a JSON summary (parts, anchors)");
  for (size_t i = 0; i < table.size(); ++i) {
    std::string flag = std::string("--") + table[i].key;
    for (auto& c : flag) if (c == '_') c = '-';
    cmd->add_option(flag, o->values[i], table[i].doc)->check(finite_range(table[i].lo, table[i].hi));
  }
  cmd->callback([o] {
    const auto& table = mouth_param_table();
    MouthParams p;
    std::string name = "command line";
    if (!o->params.empty()) {
      p = read_mouth_params(o->params);
      name = o->params;
    }
    for (size_t i = 0; i < table.size(); ++i)
      if (!std::isnan(o->values[i])) p.*table[i].member = o->values[i];
    if (o->no_tongue) p.tongue = false;
    if (o->segments) p.segments = o->segments;
    validate_mouth_params(p, name);
    if (o->print) {
      std::printf("%s\n", to_json(p).dump(2).c_str());
      return;
    }
    if (o->out.empty()) throw InputError("command line", "--output", "missing output file (-o mouth.glb)");
    GlbDocument doc = mouth_document(p);
    write_glb(o->out, doc);
    nlohmann::json j = {{"output", o->out}, {"parts", nlohmann::json::array()}, {"anchors", nlohmann::json::object()}};
    size_t tris = 0;
    for (auto& m : doc.meshes) {
      tris += m.triangle_count();
      j["parts"].push_back({{"name", m.name}, {"material", m.material}, {"triangles", m.triangle_count()}});
    }
    for (auto& a : doc.anchors) j["anchors"][a.name] = {a.position.x, a.position.y, a.position.z};
    if (o->json) {
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("wrote %s: %zu parts, %zu triangles\n", o->out.c_str(), doc.meshes.size(), tris);
    for (auto& a : doc.anchors)
      std::printf("anchor %-18s %8.4f %8.4f %8.4f\n", a.name.c_str(), a.position.x, a.position.y, a.position.z);
  });
}

}  // namespace ofl
