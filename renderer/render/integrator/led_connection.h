// Next-event estimation's last step, shared by the path tracer's surface vertices and the spatial
// transport's entry points: a point on the chosen LED (its disk, or its centre for a point LED),
// the shadow ray, and the light sample's geometry term divided by the probability `pmf` with which
// the LED was chosen (docs/transport.md, "Direct light").
#pragma once
#include "renderer/render/integrator/render_tables.h"
#include "renderer/render/trace/embree_scene.h"
#include "renderer/render/trace/path_lanes.h"
#include "renderer/render/trace/ray_counts.h"
#include "renderer/render/trace/rng.h"
#include "renderer/render/trace/sampling.h"
#include "renderer/scene/scene.h"

namespace ofl {

// x: the shading point (normals on the side the light must come from), f: its shading frame.
// Invalid (no light) when the LED faces away, the direction is below x, or the ray is blocked.
LightSample connect_to_led(const Scene& scene, const EmbreeScene& embree, const RenderTables& t, int light, double pmf,
                           const SurfacePoint& x, const Frame& f, Rng& rng, RayCounts& counts, RayLog* log);

}  // namespace ofl
