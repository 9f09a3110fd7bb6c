// Physical constants and the photon/energy conversion used at the boundaries of transport.
// Transport runs in photon units (quanta s^-1 sr^-1 m^-2 nm^-1) so that quantum yields hold;
// lights convert from watts on the way in and the film converts back on the way out.
#pragma once

namespace ofl {

constexpr double kPlanck = 6.62607015e-34;       // J s (exact, SI 2019)
constexpr double kSpeedOfLight = 299792458.0;    // m/s (exact)
constexpr double kBoltzmann = 1.380649e-23;      // J/K (exact)
constexpr double kPi = 3.14159265358979323846;

// Energy of one photon of wavelength `nm`, in joules.
inline double photon_energy_J(double nm) { return kPlanck * kSpeedOfLight / (nm * 1e-9); }
// Photons per joule at wavelength `nm` (multiply a radiometric quantity to get a quantal one).
inline double photons_per_joule(double nm) { return 1.0 / photon_energy_J(nm); }

}  // namespace ofl
