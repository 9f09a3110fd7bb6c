// An ISETCam sensor (.mat holding the struct sensorCreate makes, as variable `sensor` or any struct
// of type 'sensor') as an oralfluor camera description (camera.json, docs/camera.md). Mapping:
//   QE of channel k     color.filterSpectra(:, k) .* color.irFilter .* pixel.spectralQE on
//                       spectrum.wave (ISETCam's sensor spectral QE); R, G, B found by the first
//                       letter of color.filterNames
//   cfa                 cfa.pattern (indices into filterNames; a larger pattern must repeat a 2x2 cell)
//   pixel_pitch_um      pixel.width + pixel.widthGap (square pixels)
//   fill_factor         pixel.pdWidth * pixel.pdHeight / pitch^2
//   full_well_e         pixel.voltageSwing / pixel.conversionGain
//   read_noise_e        pixel.readNoise (V) / conversionGain
//   dark_current_e_per_s pixel.darkVoltage (V/s) / conversionGain
//   dsnu_e              sigmaOffsetFPN (V) / conversionGain;  prnu_percent: sigmaGainFPN (percent)
//   bit_depth, gain     quantization.bits; ISETCam quantises volts in steps of voltageSwing / 2^bits,
//                       so K = conversionGain 2^bits / voltageSwing DN/e-; analogGain divides volts in
//                       ISETCam ((v + analogOffset) / analogGain), so analog_gain = 1 / analogGain and
//                       black_level_dn = analogOffset / analogGain / step
//   exposure_s          integrationTime (s)
//   noise               noiseFlag: 0 none, 1 shot noise only (electronic noise terms zeroed), 2 all
// What has no counterpart (optics live in ISETCam's oi, not the sensor; the sensor's rows and cols;
// auto exposure) is listed in `notes`.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace ofl {

struct IsetSensorImport {
  nlohmann::json camera;           // a camera.json document parse_camera accepts
  std::vector<std::string> notes;  // what was assumed or left out
};

// InputError naming the file and the sensor field (e.g. "sensor.pixel.conversionGain").
IsetSensorImport import_iset_sensor(const std::filesystem::path& file);

}  // namespace ofl
