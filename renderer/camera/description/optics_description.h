// The "optics" section of a camera file as plain structs: the sensor grid, focus, PSF settings and
// a measured MTF or PSF images, parsed with errors that name the file and the field. The stage that
// uses them (the optical image between the render's radiance and the sensor) is optics.h; the
// format is docs/camera.md, "Optical image". A camera description holds one (camera_description.h).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/elements/psf.h"
#include "renderer/core/files/json_node.h"

namespace ofl {

// A measured lens MTF: one radial MTF curve per wavelength (CSV columns wavelength_nm,
// frequency_cyc_per_mm, mtf; rows of one wavelength together, frequencies increasing).
struct MtfTable {
  std::string file;
  std::vector<double> wavelength_nm;
  std::vector<std::vector<double>> freq_cyc_per_mm, mtf;
  bool empty() const { return wavelength_nm.empty(); }
  size_t nearest(double nm) const;  // index of the nearest tabulated wavelength
};

struct OpticsDescription {
  bool enabled = false;            // the camera file has an "optics" section
  int sensor_width_px = 0;         // "sensor_pixels": [width, height], required
  int sensor_height_px = 0;
  double offset_x_um = 0;          // "sensor_offset_um": [x, y], sensor centre relative to the optical axis
  double offset_y_um = 0;          //   (x right, y down, as the image)
  double focus_distance_mm = 0;    // "focus_distance_mm": object distance in focus; 0 (absent) = infinity
  bool diffraction = true;         // "diffraction": Airy PSF of the working f-number per band
  bool defocus = true;             // "defocus": blur circle from the EXR's aov.depth (needs a finite focus or a near scene)
  double psf_extent_lambda_n = 15; // "psf_extent_lambda_n" (2-100): Airy table radius in units of lambda N (the rest
                                   //   of the far rings, about 2 / (pi^2 extent) of the light, is renormalised into the kernel)
  int psf_supersample = 4;         // "psf_supersample": samples per pixel side integrating the PSF (raised
                                   //   automatically to at least 2 per lambda N)
  MtfTable mtf;                    // "mtf_file": measured radial MTF per wavelength, replaces the Airy PSF
  std::vector<PsfImage> psf_images;  // "psf_images": [{"wavelength_nm", "file", "pitch_um"}]: measured PSF
                                   //   images (EXR/TIFF/PNG first channel, or a CSV grid), replace the Airy PSF
  std::vector<std::string> psf_image_files;  // their paths (for raw.json)
  size_t nearest_psf_image(double nm) const;
};

// Parses the "optics" object (file errors name the camera file and JSON path; MTF file errors name
// the CSV, line and column).
OpticsDescription parse_optics(const JsonNode& node);
nlohmann::json optics_to_json(const OpticsDescription& o);

}  // namespace ofl
