// Measured data for `oralfluor diagnose`, read as the user has it:
//  (a) spectroradiometer spectra: a folder holding `index.csv` (one row per spectrum: a file
//      column plus any condition columns such as subject, site, light_nm, led_current_mA, date,
//      r_index) and one two-column CSV per spectrum (wavelength_nm, radiance), e.g. the
//      oe_tongue_lip folder as shipped;
//  (b) camera patches: a `patches.csv` with one row per patch (mean R, G, B and the file and
//      column of the radiance spectrum that produced them, plus condition columns).
// Every problem is an InputError naming the file and the line/column.
#pragma once
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace ofl {

// Keep rows whose `column` equals one of `values` (numbers compare as numbers: "405" == "405.0").
struct RowFilter {
  std::string column;
  std::vector<std::string> values;
};
bool cell_matches(const std::string& cell, const std::string& value);

struct MeasuredSpectrum {
  std::string file;                              // resolved path
  std::string label;                             // file name without extension
  int index_line = 0;                            // line in index.csv
  std::map<std::string, std::string> conditions; // every index column of the row
  std::vector<double> nm, value;
};

struct SpectraSet {
  std::string index_file;
  std::vector<MeasuredSpectrum> spectra;
  std::vector<std::string> notes;  // rows skipped and data warnings, in plain words
};

// `path` is a folder with index.csv, or the index CSV itself. Paths in `file_column` are tried
// relative to the index's folder, then with leading folders removed one at a time (so a copy of
// a folder whose index names files relative to a parent folder still reads as is).
SpectraSet read_spectra_index(const std::filesystem::path& path, const std::string& file_column,
                              const std::vector<RowFilter>& select);

struct CameraPatch {
  std::string id;
  int line = 0;
  std::map<std::string, std::string> conditions;
  double rgb[3] = {0, 0, 0};       // mean raw values (DN, black level not removed unless stated)
  double sd[3] = {-1, -1, -1};     // pixel standard deviation within the patch (-1: not given)
  double n_pixels = 0;             // pixels averaged (0: not given)
  double exposure = 1;             // relative exposure (time x gain), 1 when not given
  std::vector<double> nm, radiance;  // W sr^-1 m^-2 nm^-1 (or relative)
};

struct CameraPatchSet {
  std::string file;
  std::vector<CameraPatch> patches;
  std::vector<std::string> notes;
};

// Columns: patch, r_mean, g_mean, b_mean, radiance_file, radiance_column (required); r_sd, g_sd,
// b_sd, n_pixels, exposure (optional); any other column is a condition.
CameraPatchSet read_camera_patches(const std::filesystem::path& path, const std::vector<RowFilter>& select);

enum class InputKind { kSpectra, kCamera };
// A folder with index.csv (spectra) or patches.csv (camera), or a CSV whose header says which.
InputKind detect_input_kind(const std::filesystem::path& path);

}  // namespace ofl
