// `oralfluor mesh texture`: porphyrin and lesion maps in the tongue's UV space (see
// renderer/mesh/mouth/tongue_maps.h), from a tongue mesh (.glb/.gltf/.obj; the meshes whose material
// is "tongue", or all of them when none is).
#include <cstdio>
#include <memory>

#include "renderer/cli/assets/cmd_mesh_parts.h"
#include "renderer/cli/shared/commands.h"
#include "renderer/core/errors/error.h"
#include "renderer/mesh/files/gltf_reader.h"
#include "renderer/mesh/files/obj_reader.h"
#include "renderer/mesh/mouth/tongue_maps.h"

namespace ofl {

void register_texture_command(CLI::App& mesh) {
  struct Opts {
    std::string tongue, out_dir, prefix = "tongue";
    TongueMapParams p;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = mesh.add_subcommand("texture", "porphyrin and lesion maps (16-bit grayscale PNG) in a tongue's UV space");
  cmd->add_option("tongue", o->tongue, "tongue mesh (.glb, .gltf or .obj) in the mouth frame")->required();
  cmd->add_option("-o,--output-dir", o->out_dir, "folder for <prefix>_porphyrin.png, _lesion.png, _uv_layout.png")->required();
  cmd->add_option("--prefix", o->prefix, "file name prefix");
  cmd->add_option("--size", o->p.size, "texels per side")->check(CLI::Range(16, 8192));
  cmd->add_option("--porphyrin-center-frac", o->p.porphyrin_center_frac, "patch centre, fraction of the length back from the tip")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--porphyrin-radius-x-m", o->p.porphyrin_radius_x_m, "patch radius along the tongue (m)")->check(finite_positive());
  cmd->add_option("--porphyrin-radius-y-m", o->p.porphyrin_radius_y_m, "patch radius across the tongue (m)")->check(finite_positive());
  cmd->add_option("--lesion-center-frac", o->p.lesion_center_frac, "lesion centre, fraction of the length back from the tip")
      ->check(finite_range(0.0, 1.0));
  cmd->add_option("--lesion-radius-m", o->p.lesion_radius_m, "lesion radius (m)")->check(finite_positive());
  cmd->add_option("--lesion-side", o->p.lesion_side, "+1 the patient's left border, -1 the right")->check(CLI::IsMember({-1.0, 1.0}));
  cmd->add_flag("--json", o->json, "print the report (tongue frame, UV regions) as JSON");
  cmd->callback([o] {
    std::filesystem::path in(o->tongue);
    std::vector<TriangleMesh> all = in.extension() == ".obj" ? read_obj(in).meshes : read_gltf(in).meshes;
    std::vector<TriangleMesh> tongue;
    for (auto& m : all)
      if (m.material == "tongue") tongue.push_back(m);
    if (tongue.empty()) tongue = all;
    TongueMaps maps = make_tongue_maps(tongue, o->p);
    std::filesystem::path dir(o->out_dir);
    write_gray16_png(dir / (o->prefix + "_porphyrin.png"), maps.porphyrin);
    write_gray16_png(dir / (o->prefix + "_lesion.png"), maps.lesion);
    write_uv_layout_png(dir / (o->prefix + "_uv_layout.png"), maps);
    if (o->json) {
      std::printf("%s\n", maps.report.dump(2).c_str());
    } else {
      std::printf("wrote %s_{porphyrin,lesion,uv_layout}.png in %s (%d x %d)\n", o->prefix.c_str(), dir.string().c_str(),
                  o->p.size, o->p.size);
      auto box = [](const nlohmann::json& j) { return j.contains("uv_box_above_half") ? j["uv_box_above_half"].dump() : "none"; };
      std::printf("porphyrin patch: UV box (value > half) %s\n", box(maps.report["porphyrin"]).c_str());
      std::printf("lesion patch:    UV box (value > half) %s\n", box(maps.report["lesion"]).c_str());
    }
  });
}

}  // namespace ofl
