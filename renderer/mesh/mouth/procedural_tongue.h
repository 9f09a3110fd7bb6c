// The procedural tongue of the mouth generator: a superellipsoid
//   |x/a|^p + |y/b|^q + |z/c|^r <= 1   (c = c_top above the mid-plane, c_bottom below)
// whose width tapers linearly along x and whose mid-line droops parabolically towards the tip and
// the back (a shear, z -= droop * u^2 with u = +1 at the tip, -1 at the back), then
// pitched about y and placed so its tip is at x = tongue_protrusion_m. Taper and droop keep the
// volume, so the mesh's volume can be checked against the closed form
//   V = 4 a b (c_top + c_bottom) G(1+1/p) G(1+1/q) G(1+1/r) / G(1+1/p+1/q+1/r).
// UVs: u goes round the tongue (0 and 1 on the underside midline, 0.5 on the dorsal midline),
// v runs from the tip (0) to the back (1).
#pragma once
#include "renderer/mesh/mouth/mouth_params.h"
#include "renderer/mesh/geometry/triangle_mesh.h"

namespace ofl {

struct TongueShape {
  double a, b, c_top, c_bottom;  // half-length, half-width, heights above/below the mid-plane
  double p = 2.2, q = 2.6, r = 2.2;  // exponents along x, y, z
};
TongueShape tongue_shape(const MouthParams& p);

// Closed, outward-facing, smooth normals, UVs in [0,1]; material "tongue", name "tongue".
TriangleMesh make_procedural_tongue(const MouthParams& p);

}  // namespace ofl
