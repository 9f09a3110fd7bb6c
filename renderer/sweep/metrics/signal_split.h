// Splitting the camera signal by where the light came from. The renderer keeps the fluorescence
// (light re-radiated by a fluorophore at least once, whatever happened to it afterwards) as its own
// layer; everything else in the radiance is reflected LED light. The reflected part is split once
// more by wavelength:
//   leaked excitation  reflected light in output bands inside the LED's emission band: the
//                      excitation light itself, which reaches the sensor only through the emission
//                      filter's blocking (its OD) or an edge shifted by the angle of incidence;
//   reflected          reflected light in the other bands: the LED's own out-of-band tail (what
//                      its short-pass lets through) reflected by the tissue, plus, for white LEDs,
//                      ordinary reflectance.
// An output band is inside the LED's emission band when the scene's summed, filtered LED spectral
// intensity reaches `threshold` x its peak at some transport-grid wavelength inside the band
// ([lo, hi] of the band). The camera is linear in radiance, so the expected electrons of the three
// parts add up to those of the whole image exactly.
#pragma once
#include <vector>

#include "renderer/camera/description/camera_description.h"
#include "renderer/camera/sensor/expected_signal.h"
#include "renderer/image/spectral_image.h"
#include "renderer/spectral/spectra/wavelength_grid.h"

namespace ofl {

// Per output band: inside the LED's emission band?
std::vector<bool> led_band_mask(const std::vector<double>& band_lo, const std::vector<double>& band_hi,
                                const WavelengthGrid& grid, const std::vector<double>& led_intensity, double threshold);

struct SignalSplit {
  // Expected photo-electrons of each pixel's own CFA channel ([y * width + x]), per part.
  std::vector<float> fluorescence, reflected, leak;
};

// Runs the camera's expected-signal model on each part of the radiance. Without a fluorescence
// layer the fluorescence part is zero.
SignalSplit split_signal(const SpectralImage& radiance, const std::vector<bool>& in_led_band,
                         const CameraDescription& cam, const FieldGeometry& geometry);

}  // namespace ofl
