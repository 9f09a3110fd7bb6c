// Geometry the spatial transport of layered tissue cannot carry light across as the scene intends,
// said out loud before a render (docs/layered-tissue.md, "Lateral transport", and
// docs/bad-inputs.md): for every mesh whose material (or one of whose regions) uses
// "transport": "spatial",
// - edges wound inconsistently (two triangles traversing a shared edge the same way): a probe cannot
//   tell the near side of the surface from the far side there, and light moving sideways across
//   them is lost;
// - parts thinner than the distance light travels sideways in the material (the radius holding 90 %
//   of the diffuse reflectance at its reddest rendered wavelength): the stack is taken as
//   semi-infinite, so light that would reach the far surface stays on the near one.
// Each warning names the material and the mesh.
#pragma once
#include <string>
#include <vector>

#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/trace/embree_scene.h"

namespace ofl {

std::vector<std::string> spatial_geometry_warnings(const Scene& scene, const EmbreeScene& embree, const RenderTables& tables);

}  // namespace ofl
