// The optical-image stage of `oralfluor camera`: between the render's spectral radiance and the
// sensor. Used when the camera file has an "optics" section (docs/camera.md, "Optical image").
//
//   "optics": { "sensor_pixels": [1280, 800], "sensor_offset_um": [0, 0], "focus_distance_mm": 40,
//               "diffraction": true, "defocus": true, "psf_extent_lambda_n": 15, "psf_supersample": 4,
//               "mtf_file": "lens_mtf.csv" }    (or "psf_images": [{"wavelength_nm": 550, "file": "psf550.exr", "pitch_um": 0.5}])
//
// The pixel pitch is the sensor's "pixel_pitch_um", focal length and f-number are the lens's
// "focal_length_mm" (required with optics) and "f_number": each number lives in one place.
//
// 1. Geometry. The render is a pinhole image, uniform in tan(angle): render pixel i spans
//    tan_x in [(2 i / W - 1) t_w, (2 (i + 1) / W - 1) t_w], t_w = tan(vfov / 2) W / H. The lens
//    puts the chief ray of angle theta at x = v tan(theta) on the sensor plane, v the image
//    distance (v = f d_f / (d_f - f) when focused at d_f, f at infinity), so every render pixel
//    maps onto a square of side p_r = v 2 tan(vfov / 2) / H on the sensor plane. The sensor's
//    centre sits at "sensor_offset_um" from the optical axis; the image is taken upright (the
//    readout undoes the lens's inversion), x right, y down, as in the render.
// 2. Optical image (on the render grid, pitch p_r): each band's radiance is convolved with the PSF
//    at the band's centre wavelength: Airy pattern of the working f-number, or the measured MTF's
//    PSF, convolved with the defocus blur circle of the pixel's depth (scene depth from the EXR's
//    "aov.depth"), c = A |v - v_d| / v_d (A = f / N the aperture diameter, v_d the image distance
//    of depth d), i.e. c = A f |d - d_f| / (d (d_f - f)). Each render pixel spreads its light with
//    its own kernel (depth layers: blur quantised in 1/4 render pixel steps up to 2.5 pixels, 10 %
//    steps beyond); occlusion at depth edges is ignored. Light is conserved: kernels sum to 1 and the image is extended by its edge pixels.
// 3. Resampling onto the sensor grid: every sensor pixel gets the radiance averaged over its area
//    on the sensor plane, from the exact overlap areas with the render pixels' squares (separable:
//    overlap lengths in x times in y). Sensor pixels (or parts) outside the render's field of view
//    get zero, with a warning naming how many and where.
// The result is the radiance at the sensor grid ("equivalent radiance"); the camera equation
// E = pi T L / (1 + 4 N^2 (1 - m)^2) cos^4(theta) stays where it was (expected_signal.h), with the
// field angles of the sensor pixels (FieldGeometry with the axis offset).
// The section's fields as parsed (OpticsDescription) are in optics_description.h.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "renderer/camera/description/optics_description.h"
#include "renderer/image/spectral_image.h"

namespace ofl {

struct CameraDescription;
struct LensDescription;

// Image distance v in mm for the lens focused at the optics' focus distance (f at infinity).
double image_distance_mm(const LensDescription& lens, const OpticsDescription& o);

// Where the render's pixels land on the sensor grid: render pixel edge i (0..W) at sensor pixel
// coordinate u = x0 + scale i, edge j (0..H) at y0 + scale j (sensor pixel (I, J) spans [I, I+1] x [J, J+1]).
struct RenderOnSensor {
  double x0 = 0, y0 = 0, scale = 1;  // scale = render pixel size / sensor pixel pitch
  double render_pitch_um = 0;        // side of a render pixel's square on the sensor plane
};
RenderOnSensor map_render_to_sensor(int render_w, int render_h, double vfov_deg, double image_distance_mm,
                                    double pitch_um, const OpticsDescription& o);

// Overlap lengths of render intervals [x0 + s i, x0 + s (i + 1)] with sensor intervals [I, I + 1].
struct OverlapWeights {
  std::vector<int> first;                  // per sensor index: first render index with a weight
  std::vector<std::vector<double>> w;      // per sensor index: weights of render indices first, first + 1, ...
  double coverage(int I) const;            // sum of the weights of sensor index I (0..1)
};
OverlapWeights overlap_weights(int render_n, int sensor_n, double x0, double scale);

// Area-correct resampling: each band of `img` averaged over every sensor pixel's area (zero where
// no render pixel lies). `coverage` (optional) gets the covered fraction of each sensor pixel.
SpectralImage resample_to_sensor(const SpectralImage& img, int sensor_w, int sensor_h, const RenderOnSensor& m,
                                 std::vector<float>* coverage);

// A per-pixel render plane (aov.material, say) seen at every sensor pixel's centre (nearest render
// pixel; `outside` where the centre lies outside the render's field of view), from the mapping
// the stage records as "render_fov_on_sensor_px" ([x0, y0, x1, y1]) in raw.json's "optics".
std::vector<float> render_plane_on_sensor(const std::vector<float>& plane, int render_w, int render_h, int sensor_w,
                                          int sensor_h, const std::vector<double>& fov_on_sensor_px, float outside);

// Blur circle diameter on the sensor (um) of an object at axial distance d_mm (<= 0 or infinite: at infinity).
double blur_circle_um(const LensDescription& lens, const OpticsDescription& o, double d_mm);

// The optical image on the render grid: every band convolved with its PSF (diffraction or
// measured MTF, with the defocus of each pixel's depth when `depth_mm` is given, else in focus).
// `info` gets the kernel sizes and depth layers used.
SpectralImage blur_optical_image(const SpectralImage& img, const LensDescription& lens, const OpticsDescription& o,
                                 double render_pitch_um, const std::vector<float>* depth_mm, nlohmann::json* info);

struct OpticalImage {
  SpectralImage image;               // radiance averaged over each sensor pixel (W sr^-1 m^-2 nm^-1)
  double axis_x_px = 0, axis_y_px = 0;  // optical axis relative to the sensor centre, in pixels
  nlohmann::json info;               // what the stage did (for the summary)
  std::vector<std::string> warnings;
};

// The whole stage: checks (focal length, render field of view), PSF on the render grid,
// resampling, and the warning about sensor pixels outside the render's field of view.
OpticalImage form_optical_image(const SpectralImage& radiance, const CameraDescription& cam,
                                const std::string& radiance_file);

}  // namespace ofl
