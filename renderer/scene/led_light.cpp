#include "renderer/scene/led_light.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include <glm/geometric.hpp>

#include "renderer/core/files/csv.h"
#include "renderer/core/errors/error.h"
#include "renderer/scene/ies_profile.h"
#include "renderer/spectral/spectrum_json.h"
#include "renderer/spectral/spectra/units.h"

namespace ofl {

double LedProfile::cos_power_from_half_angle(double half_deg) {
  return std::log(0.5) / std::log(std::cos(half_deg * kPi / 180.0));
}

// The bin of table_start that holds cos(theta) = c, for c inside the table.
static size_t start_bin(const LedProfile& p, double c) {
  const double s_lo = std::sqrt(1.0 - p.table_cos.back()), s_hi = std::sqrt(1.0 - p.table_cos.front());
  const double x = (std::sqrt(std::max(0.0, 1.0 - c)) - s_lo) / (s_hi - s_lo) * double(p.table_start.size());
  return std::min(p.table_start.size() - 1, size_t(std::max(0.0, x)));
}

// The first knot with table_cos > c (what std::upper_bound gives), for front < c < back.
static size_t knot_above(const LedProfile& p, double c) {
  const auto& tc = p.table_cos;
  if (p.table_start.empty()) return std::upper_bound(tc.begin(), tc.end(), c) - tc.begin();
  size_t i = p.table_start[start_bin(p, c)];
  while (tc[i] <= c) ++i;                  // the bin starts at or below c's knot pair...
  while (i > 1 && tc[i - 1] > c) --i;      // ...and rounding at a bin edge cannot move it
  return i;
}

double LedProfile::eval(double c) const {
  if (c <= 0) return 0.0;
  if (table_cos.empty()) {  // cos^m; the isotropic and the Lambertian emitter without pow (the same values)
    if (cos_power == 0) return 1.0;
    return cos_power == 1 ? c : std::pow(c, cos_power);
  }
  if (c <= table_cos.front()) return table_value.front();
  if (c >= table_cos.back()) return table_value.back();
  size_t i = knot_above(*this, c);
  double t = (c - table_cos[i - 1]) / (table_cos[i] - table_cos[i - 1]);
  return table_value[i - 1] * (1 - t) + table_value[i] * t;
}

double LedProfile::max_beyond(double c) const {
  if (c <= 0) return 0.0;
  if (table_cos.empty()) return eval(c);  // cos^m does not grow with the angle
  if (c <= table_cos.front()) return table_value.front();
  const std::vector<double>& env = table_envelope;
  if (env.size() != table_cos.size()) {  // not indexed: the largest value anywhere
    double m = 0;
    for (double v : table_value) m = std::max(m, v);
    return m;
  }
  if (c >= table_cos.back()) return env.back();
  return env[knot_above(*this, c)];
}

double LedProfile::choice_bound(double c) const {
  if (!table_cos.empty() || power_bound_m != cos_power || power_bound.size() != size_t(kPowerBoundBins) + 1)
    return max_beyond(c);
  if (c <= 0) return 0.0;
  const size_t k = std::min<size_t>(size_t(std::ceil(c * kPowerBoundBins)), size_t(kPowerBoundBins));
  const double v = power_bound[k];
  return v > 0 ? v : max_beyond(c);  // underflow of a steep power: the exact value
}

void LedProfile::index_table() {
  power_bound.clear();
  power_bound_m = -1;
  if (table_cos.empty()) {
    for (int k = 0; k <= kPowerBoundBins; ++k) power_bound.push_back(std::pow(double(k) / kPowerBoundBins, cos_power));
    power_bound_m = cos_power;
  }
  table_start.clear();
  table_envelope.clear();
  if (table_cos.size() < 2) return;
  double m = 0;
  for (double v : table_value) table_envelope.push_back(m = std::max(m, v));
  // The first knot (from the largest angle) with a positive value: below the knot before it, and
  // below 0, P is 0 (linear interpolation between two zeros, or the constant below the table).
  size_t k = 0;
  while (k < table_value.size() && !(table_value[k] > 0)) ++k;
  zero_at_or_below = k == 0 ? 0.0 : k == table_value.size() ? 1.0 : std::max(0.0, table_cos[k - 1]);
  const size_t bins = 2 * table_cos.size();
  const double s_lo = std::sqrt(1.0 - table_cos.back()), s_hi = std::sqrt(1.0 - table_cos.front());
  for (size_t b = 0; b < bins; ++b) {
    // Bin b spans sqrt(1 - c) in [s_lo + b ds, s_lo + (b + 1) ds] (bin 0 at the axis): its
    // smallest cos is at the top end, and the knot above that is where a search may start.
    const double s_top = s_lo + (s_hi - s_lo) * double(b + 1) / double(bins);
    const double c_min = 1.0 - s_top * s_top;
    size_t i = std::upper_bound(table_cos.begin(), table_cos.end(), c_min) - table_cos.begin();
    table_start.push_back(unsigned(std::clamp<size_t>(i, 1, table_cos.size() - 1)));
  }
}

double LedProfile::solid_angle_integral() const {
  if (table_cos.empty()) return 2.0 * kPi / (cos_power + 1.0);
  // 2 pi * integral_0^1 P(mu) d mu, P piecewise linear in mu; fine midpoint rule.
  const int n = 20000;
  double s = 0;
  for (int i = 0; i < n; ++i) s += eval((i + 0.5) / n);
  return 2.0 * kPi * s / n;
}

double LedLight::area() const { return kPi * radius_m * radius_m; }

// cos(max(0, angle - spread)) from the cosine of `angle` and the sine and cosine of `spread`.
static double cos_less(double cos_a, double sin_spread, double cos_spread) {
  if (cos_a >= cos_spread) return 1.0;  // angle <= spread
  const double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
  return cos_a * cos_spread + sin_a * sin_spread;
}

double LedLight::irradiance_bound(const glm::dvec3& p, const glm::dvec3& ns, const glm::dvec3& ng) const {
  const glm::dvec3 to = position - p;
  const double d2 = glm::dot(to, to);
  if (!(d2 > 0)) return 0.0;
  const double d = std::sqrt(d2);
  const glm::dvec3 w = to / d;
  const double cos_l = -glm::dot(w, axis), cos_s = glm::dot(w, ns), cos_g = glm::dot(w, ng);
  if (is_point()) {
    if (!(cos_l > profile.zero_at_or_below && cos_s > 0 && cos_g > 0)) return 0.0;
    return intensity_W_sr * profile.eval(cos_l) * cos_s / d2;
  }
  // Every point of the disk lies in its plane: p must be in front of it.
  if (!(glm::dot(p - position, axis) > 0)) return 0.0;
  // Seen from p the disk lies within `spread` of its centre's direction (at the LED too: the angle
  // between the axis and the direction from a disk point to p differs from cos_l's by at most it).
  // Closer than the radius, the disk can be in any direction.
  if (d <= radius_m) return intensity_W_sr * profile.max_beyond(1.0) / d2;
  const double sin_spread = radius_m / d, cos_spread = std::sqrt(1.0 - sin_spread * sin_spread);
  const double s = cos_less(cos_s, sin_spread, cos_spread), g = cos_less(cos_g, sin_spread, cos_spread);
  if (!(s > 0 && g > 0)) return 0.0;
  const double prof = profile.choice_bound(cos_less(cos_l, sin_spread, cos_spread));
  return intensity_W_sr * prof * s / d2;
}

// Relative intensity against polar angle from an IES LM-63 photometric file (types C and B with
// the vertical angle measured from the LED axis): candela averaged over the horizontal angles.
std::vector<std::pair<double, double>> read_ies_profile(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot open IES file");
  std::string line;
  int lineno = 0;
  bool tilt = false;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.rfind("TILT=", 0) == 0) {
      if (line.substr(5, 4) != "NONE") throw InputError(file.string(), "line " + std::to_string(lineno), "only TILT=NONE is supported");
      tilt = true;
      break;
    }
  }
  if (!tilt) throw InputError(file.string(), "", "no TILT= line: not an IES LM-63 file");
  std::vector<double> v;
  std::string tok;
  while (in >> tok) {
    char* end = nullptr;
    double x = std::strtod(tok.c_str(), &end);
    if (end == tok.c_str() || *end != '\0' || !std::isfinite(x)) throw InputError(file.string(), "after TILT", "not a number: \"" + printable(tok, 40) + "\"");
    v.push_back(x);
  }
  if (v.size() < 13) throw InputError(file.string(), "header", "truncated photometric header");
  // The counts are read as numbers: check them as numbers (finite, whole, bounded) before they
  // become integers, so that a huge or fractional count is an input error, not undefined behaviour.
  auto count = [&](size_t i, const char* what, double lo) {
    constexpr double kMaxAngles = 10000;
    double x = v[i];
    if (!(x >= lo && x <= kMaxAngles) || x != std::floor(x))
      throw InputError(file.string(), std::string("header ") + what,
                       "must be a whole number from " + std::to_string(int(lo)) + " to " + std::to_string(int(kMaxAngles)) +
                           ", found " + std::to_string(x));
    return size_t(x);
  };
  const size_t nv = count(3, "vertical angle count", 2), nh = count(4, "horizontal angle count", 1);
  const size_t need = 13 + nv + nh + nv * nh;  // at most 13 + 2e4 + 1e8: no overflow
  if (v.size() < need)
    throw InputError(file.string(), "candela table", "expected " + std::to_string(need) + " numbers, found " + std::to_string(v.size()));
  std::vector<std::pair<double, double>> rows;
  for (size_t i = 0; i < nv; ++i) {
    double angle = v[13 + i], sum = 0;
    for (size_t h = 0; h < nh; ++h) {
      double cd = v[13 + nv + nh + h * nv + i];
      if (cd < 0)
        throw InputError(file.string(), "candela value " + std::to_string(h * nv + i + 1),
                         "negative candela " + std::to_string(cd) + " (vertical angle " + std::to_string(angle) + " deg)");
      sum += cd;
    }
    if (angle <= 90.0 + 1e-9) rows.push_back({angle, sum / nh});
  }
  if (!rows.empty() && rows.front().first == 0.0 && !(rows.front().second > 0))
    throw InputError(file.string(), "candela table", "zero candela on the LED axis (vertical angle 0): the profile cannot be normalised");
  return rows;
}

static LedProfile parse_profile(const JsonNode& n) {
  LedProfile p;
  n.check_keys({"half_angle_deg", "cos_power", "table", "table_file", "ies_file"});
  int given = n.has("half_angle_deg") + n.has("cos_power") + n.has("table") + n.has("table_file") + n.has("ies_file");
  if (given != 1) n.fail("give exactly one of half_angle_deg, cos_power, table, table_file, ies_file");
  if (auto h = n.find("half_angle_deg")) {
    p.cos_power = LedProfile::cos_power_from_half_angle(h->number(0.5, 89.5));
    p.index_table();
    return p;
  }
  if (auto m = n.find("cos_power")) {
    p.cos_power = m->number(0.0, 1e4);
    p.index_table();
    return p;
  }
  std::vector<std::pair<double, double>> rows;  // (angle_deg, relative)
  if (auto t = n.find("table")) {
    for (size_t i = 0; i < t->size(); ++i) {
      JsonNode r = t->at(i);
      if (!r.is_array() || r.size() != 2) r.fail("expected [angle_deg, relative_intensity]");
      rows.push_back({r.at(0).number(0.0, 90.0), r.at(1).number(0.0)});
    }
  } else if (auto ies = n.find("ies_file")) {
    rows = ies->read_file([](const std::filesystem::path& p) { return read_ies_profile(p); });
  } else {
    auto file = n.at("table_file").existing_file();
    CsvNumeric c = read_numeric_csv(file);
    if (c.header.size() < 2) throw InputError(c.file, "", "expected columns angle_deg, relative_intensity");
    for (size_t i = 0; i < c.rows.size(); ++i) {
      double a = c.rows[i][0], v = c.rows[i][1];
      if (!std::isfinite(a) || !std::isfinite(v) || a < 0 || a > 90 || v < 0)
        throw InputError(c.file, "line " + std::to_string(c.lines[i]), "angle must be 0..90 deg and intensity >= 0");
      rows.push_back({a, v});
    }
  }
  if (rows.size() < 2) n.fail("an angular table needs at least two rows");
  for (size_t i = 1; i < rows.size(); ++i)
    if (!(rows[i].first > rows[i - 1].first)) n.fail("table angles must increase");
  if (rows.front().first != 0.0) n.fail("the angular table must start at 0 degrees");
  double p0 = rows.front().second;
  if (!(p0 > 0)) n.fail("on-axis relative intensity must be positive");
  // Store by increasing cos(theta), i.e. decreasing angle.
  for (auto it = rows.rbegin(); it != rows.rend(); ++it) {
    p.table_cos.push_back(std::cos(it->first * kPi / 180.0));
    p.table_value.push_back(it->second / p0);
  }
  p.index_table();
  return p;
}

static void set_frame(LedLight& l) {
  glm::dvec3 helper = std::fabs(l.axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  l.tangent = glm::normalize(glm::cross(helper, l.axis));
  l.bitangent = glm::cross(l.axis, l.tangent);
}

std::vector<RingPlacement> led_ring_placement(const glm::dvec3& c, const glm::dvec3& a, const glm::dvec3& reference,
                                              double r, int count, double tilt_deg, double start_deg) {
  glm::dvec3 e1 = glm::normalize(reference - glm::dot(reference, a) * a);
  glm::dvec3 e2 = glm::cross(a, e1);
  std::vector<RingPlacement> out;
  double tilt = tilt_deg * kPi / 180.0;
  for (int i = 0; i < count; ++i) {
    double phi = start_deg * kPi / 180.0 + 2.0 * kPi * i / count;
    glm::dvec3 radial = std::cos(phi) * e1 + std::sin(phi) * e2;
    // Tilting toward the axis turns the LED's axis from a toward -radial.
    out.push_back({c + r * radial, glm::normalize(std::cos(tilt) * a - std::sin(tilt) * radial)});
  }
  return out;
}

static void parse_emitter(const JsonNode& n, const WavelengthGrid& grid, LedLight& l);

LedLight parse_led(const JsonNode& n, const WavelengthGrid& grid) {
  n.check_keys({"type", "name", "spd", "filter", "filters", "radiant_intensity_W_sr", "flux_W", "profile", "radius_m",
                "position", "axis", "target"});
  LedLight l;
  l.name = n.string_or("name", "");
  l.position = n.at("position").vec3();
  if (n.has("axis") == n.has("target")) n.fail("give exactly one of axis or target");
  if (auto a = n.find("axis")) l.axis = a->unit_vec3();
  else {
    glm::dvec3 d = n.at("target").vec3() - l.position;
    if (glm::length(d) < 1e-12) n.at("target").fail("target equals position");
    l.axis = glm::normalize(d);
  }
  set_frame(l);
  parse_emitter(n, grid, l);
  return l;
}

// {"type": "led_ring", "count": 6, "ring_radius_m": 0.01, "center": [...], "axis": [...] | "target": [...],
//  "tilt_deg": 10 | "aim_distance_m": 0.05, "start_deg": 0, "reference": [0, 0, 1], ...LED emitter fields}
static std::vector<LedLight> parse_led_ring(const JsonNode& n, const WavelengthGrid& grid) {
  n.check_keys({"type", "name", "spd", "filter", "filters", "radiant_intensity_W_sr", "flux_W", "profile", "radius_m",
                "count", "ring_radius_m", "center", "axis", "target", "tilt_deg", "aim_distance_m", "start_deg", "reference"});
  int count = n.at("count").integer(1, 1000);
  double r = n.at("ring_radius_m").number(0.0, 10.0);
  glm::dvec3 c = n.at("center").vec3();
  if (n.has("axis") == n.has("target")) n.fail("give exactly one of axis or target");
  glm::dvec3 a;
  if (auto ax = n.find("axis")) a = ax->unit_vec3();
  else {
    glm::dvec3 d = n.at("target").vec3() - c;
    if (glm::length(d) < 1e-12) n.at("target").fail("target equals center");
    a = glm::normalize(d);
  }
  if (n.has("tilt_deg") && n.has("aim_distance_m")) n.fail("give at most one of tilt_deg or aim_distance_m");
  double tilt = n.number_or("tilt_deg", 0.0, -89.0, 89.0);
  if (auto d = n.find("aim_distance_m")) tilt = std::atan2(r, d->positive()) * 180.0 / kPi;
  glm::dvec3 ref = n.find("reference") ? n.at("reference").unit_vec3() : (std::fabs(a.z) < 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0));
  if (glm::length(glm::cross(ref, a)) < 1e-6) n.at("reference").fail("reference is parallel to the ring axis");
  LedLight proto;
  parse_emitter(n, grid, proto);
  std::vector<LedLight> out;
  auto places = led_ring_placement(c, a, ref, r, count, tilt, n.number_or("start_deg", 0.0));
  for (size_t i = 0; i < places.size(); ++i) {
    LedLight l = proto;
    l.name = n.string_or("name", "ring") + "[" + std::to_string(i) + "]";
    l.position = places[i].position;
    l.axis = places[i].axis;
    set_frame(l);
    out.push_back(std::move(l));
  }
  return out;
}

std::vector<LedLight> parse_lights(const JsonNode& n, const WavelengthGrid& grid) {
  std::string type = n.string_or("type", "led");
  if (type == "led") return {parse_led(n, grid)};
  if (type == "led_ring") return parse_led_ring(n, grid);
  n.at("type").fail("unknown light type \"" + type + "\" (expected led, led_ring)");
}

// The emitter itself: size, angular profile, spectrum, filters, intensity.
static void parse_emitter(const JsonNode& n, const WavelengthGrid& grid, LedLight& l) {
  l.radius_m = n.number_or("radius_m", 0.0, 0.0, 1.0);
  l.profile = n.find("profile") ? parse_profile(n.at("profile")) : LedProfile{};

  JsonNode spd_node = n.at("spd");
  std::vector<double> s = tabulate(parse_spectrum(spd_node, SpectrumKind::kEmission), grid);
  check_tabulated(spd_node, s, grid, SpectrumKind::kEmission);
  double area = integrate(s, grid);
  if (!(area > 0)) spd_node.fail("SPD is zero over the wavelength grid");
  for (double& v : s) v /= area;  // unit integral over the grid

  if (n.has("radiant_intensity_W_sr") == n.has("flux_W")) n.fail("give exactly one of radiant_intensity_W_sr or flux_W");
  double i0 = n.has("radiant_intensity_W_sr") ? n.at("radiant_intensity_W_sr").number(0.0)
                                              : n.at("flux_W").number(0.0) / l.profile.solid_angle_integral();
  // Filters act after the LED's own output is fixed: they remove power.
  std::vector<JsonNode> filters;
  if (auto f = n.find("filter")) filters.push_back(*f);
  if (auto fs = n.find("filters"))
    for (size_t i = 0; i < fs->size(); ++i) filters.push_back(fs->at(i));
  // Any spectrum form of docs/scene-format.md ("Spectra") read as a transmittance: a CSV name, a
  // constant, points, the filter types (at normal incidence: the light's own filter sits on its axis).
  for (auto& f : filters) {
    auto t = tabulate(parse_spectrum(f, SpectrumKind::kTransmittance), grid);
    check_tabulated(f, t, grid, SpectrumKind::kTransmittance);
    for (size_t i = 0; i < s.size(); ++i) s[i] *= t[i];
  }
  l.spectral_intensity.resize(s.size());
  l.spectral_photons.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    l.spectral_intensity[i] = i0 * s[i];
    l.spectral_photons[i] = l.spectral_intensity[i] * photons_per_joule(grid.wavelength(static_cast<int>(i)));
  }
  l.intensity_W_sr = integrate(l.spectral_intensity, grid);
  l.power_W = l.intensity_W_sr * l.profile.solid_angle_integral();
}

}  // namespace ofl
