// ISETCam-style spectral files (.mat): the variables `wavelength` (nm, a vector of N values) and
// `data` (N x k: one column per spectrum), optionally `comment` (text) and `filterNames` (a cell of
// k names, as colour-filter files carry), as ISETCam's ieSaveSpectralFile / ieSaveColorFilter write
// them. Read into the same table a spectrum CSV gives (first column wavelength, then one named
// column per spectrum), so that a .mat works wherever a spectrum CSV is accepted.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "renderer/core/files/csv.h"

namespace ofl {

// Columns are named by `filterNames` when present, else "data" (one column) or "1".."k".
// InputError naming the variable for a missing `wavelength`/`data`, mismatched sizes, NaN,
// non-increasing wavelengths. Rows of the table are numbered from 1 in `lines`.
CsvNumeric read_spectrum_mat(const std::filesystem::path& file);

// Writes wavelength (N x 1), data (N x k), filterNames (when names are given) and comment.
void write_spectrum_mat(const std::filesystem::path& file, const std::vector<double>& nm,
                        const std::vector<std::vector<double>>& columns, const std::vector<std::string>& names = {},
                        const std::string& comment = "");

}  // namespace ofl
