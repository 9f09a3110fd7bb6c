// LEDs: radiant intensity I(theta, lambda) = I0 * S(lambda) * P(theta) with S the SPD (times any
// filters) normalised to unit integral over the transport grid before filtering, P an angular
// profile with P(0) = 1 (Lambertian-power cos^m with m from the half-angle, or a measured
// angle/relative-intensity table), a disk emitter of radius a (0 = point), a position and an axis.
// A disk of area A = pi a^2 has radiance L(theta) = I0 S P(theta) / (A cos theta), so its far field
// is exactly I(theta); m = 1 gives a uniform Lambertian disk.
#pragma once
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "renderer/core/files/json_node.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

struct LedProfile {
  double cos_power = 1.0;           // used when the table is empty
  std::vector<double> table_cos;    // increasing cos(theta) (from the angle table), with
  std::vector<double> table_value;  // relative intensity, 1 on axis
  // Filled by index_table() (parse_led does it): where to start looking for cos(theta) in the table,
  // by bins uniform in sqrt(1 - cos) (nearly uniform in angle), so eval finds its knot pair in a
  // step or two instead of a binary search; and per knot the largest value at that knot or any
  // larger angle (for max_beyond). eval gives the same value with or without them.
  std::vector<unsigned> table_start;
  std::vector<double> table_envelope;
  // P is 0 for every cos(theta) <= zero_at_or_below (0 = only behind the emitter). index_table()
  // sets it from the table; a cos^m profile keeps 0.
  double zero_at_or_below = 0;
  double eval(double cos_theta) const;  // P(theta), 0 behind the emitter
  // An upper bound of P(theta') over every theta' >= theta (cos theta' <= cos_theta), exact for
  // cos^m; 0 only where P is 0 at theta and at every larger angle. For light selection over the
  // directions a disk emitter covers (renderer/render/trace/light_choice.h).
  double max_beyond(double cos_theta) const;
  // A bound of max_beyond for light selection, cheaper: for a cos^m profile read from power_bound
  // (the power at the first tabulated cosine at or above cos_theta, at most a few % above c^m near
  // the axis), otherwise max_beyond itself. Never below max_beyond, and positive wherever it is.
  double choice_bound(double cos_theta) const;
  // Filled by index_table() for a cos^m profile: c^m at kPowerBoundBins + 1 cosines spaced evenly
  // over [0, 1], for the power power_bound_m (choice_bound ignores it once cos_power has changed).
  static constexpr int kPowerBoundBins = 256;
  std::vector<double> power_bound;
  double power_bound_m = -1;
  double solid_angle_integral() const;  // integral of P over the sphere (sr)
  void index_table();                   // fills table_start, table_envelope and power_bound
  static double cos_power_from_half_angle(double half_angle_deg);  // cos^m(half) = 1/2
};

struct LedLight {
  std::string name;
  glm::dvec3 position{0, 0, 0};
  glm::dvec3 axis{0, 0, -1};
  glm::dvec3 tangent{1, 0, 0}, bitangent{0, 1, 0};  // frame of the emitting disk
  double radius_m = 0;
  LedProfile profile;
  double intensity_W_sr = 0;                 // I0 over the grid (after filters: see filtered_intensity)
  std::vector<double> spectral_intensity;    // I0 S(lambda) with filters, W sr^-1 nm^-1 on the grid
  std::vector<double> spectral_photons;      // same in photons s^-1 sr^-1 nm^-1
  int spd_group = 0;                         // lights with identical spectra share a group
  double power_W = 0;                        // total flux with filters (for light selection)

  double area() const;
  bool is_point() const { return radius_m <= 0; }
  // How much this LED can light a surface point p with shading normal ns and geometric normal ng
  // (both unit, on the side the light must arrive from): for a point LED the unoccluded irradiance
  // I0 P(theta) cos(ns) / r^2 itself, 0 when cos(ns) or cos(ng) is not positive; for a disk an
  // estimate from its centre with P and the cosines bounded over every direction the disk covers,
  // so that it is 0 only where no point of the disk can light p. Light selection weights.
  double irradiance_bound(const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng) const;
};

// Parses one entry of "lights" (see docs/scene-format.md) on the given grid: an "led" gives one
// light, an "led_ring" gives `count` identical LEDs evenly spaced on a circle.
std::vector<LedLight> parse_lights(const JsonNode& node, const WavelengthGrid& grid);
LedLight parse_led(const JsonNode& node, const WavelengthGrid& grid);

// Positions and axes of a ring of LEDs: centre c, ring axis a (unit; the LEDs face along it),
// ring radius r, each LED tilted by tilt_deg toward the axis (positive converges), first LED at
// start_deg measured from `reference` (a unit vector perpendicular to a).
struct RingPlacement {
  glm::dvec3 position, axis;
};
std::vector<RingPlacement> led_ring_placement(const glm::dvec3& c, const glm::dvec3& a, const glm::dvec3& reference,
                                              double r, int count, double tilt_deg, double start_deg);

}  // namespace ofl
