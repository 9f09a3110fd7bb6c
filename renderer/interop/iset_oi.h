// The camera's optical image as an ISETCam optical image (`oi`), so that ISETCam's own sensor
// (sensorCompute) can run on oralfluor's optics. The struct (variable `oi` of a .mat file) holds
// the fields ISETCam's oiGet and sensorCompute read:
//   oi.type             'opticalimage'
//   oi.name             text
//   oi.spectrum.wave    wavelengths (nm, column): the radiance EXR's band centres
//   oi.data.photons     single, rows x cols x nWave: spectral irradiance at the sensor plane in
//                       photons s^-1 m^-2 nm^-1 on the sensor's pixel grid, per band b
//                         E_b = pi / (1 + 4 N^2 (1 - m)^2) cos^4(theta) L_b <T(lambda) lambda / (h c)>_b
//                       L the radiance after the optics stage (renderer/camera/optics/optics.h:
//                       PSF and resampling onto "sensor_pixels", when the camera has "optics";
//                       else the radiance on its own grid), T the lens transmittance times the
//                       filter stack at the pixel's angles (renderer/camera/elements/filter_stack.h),
//                       <>_b the mean over the band. This is the irradiance oralfluor's sensor
//                       integrates (renderer/camera/sensor/expected_signal.h): QE x pixel area x
//                       fill x exposure x band width gives its electrons. The filters are in the
//                       oi: an ISETCam sensor run on it should be the bare sensor.
//   oi.data.bitDepth    32
//   oi.wAngular         horizontal field of view (deg) chosen so that ISETCam's oi width
//                       2 f tan(wAngular / 2) (f = optics.focalLength) is cols x pixel pitch: one
//                       oi sample per sensor pixel
//   oi.optics           type 'optics', name, model 'skip' (already applied), fNumber,
//                       focalLength (m; the lens's, else the image distance the field of view implies)
//   oi.metadata         source, camera, units, pixelPitchM, what the optics stage did (JSON text)
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/camera/description/camera_description.h"
#include "renderer/image/spectral_image.h"
#include "renderer/formats/mat_file.h"

namespace ofl {

struct IsetOi {
  MatValue oi;                        // the struct written as variable "oi"
  int rows = 0, cols = 0;
  double hfov_deg = 0, focal_length_m = 0, pixel_pitch_m = 0;
  double photon_sum = 0;              // sum of data.photons (as stored, single precision)
  std::vector<std::string> warnings;  // the optics stage's and the geometry's
};

// InputError (file = `source`) when neither the lens focal length nor the render's field of view
// gives the sensor's geometry.
IsetOi make_iset_oi(const SpectralImage& radiance, const CameraDescription& cam, const std::string& source);
void write_iset_oi(const std::filesystem::path& file, const IsetOi& oi);

}  // namespace ofl
