// MATLAB .mat files through libmatio: the values ISETCam and isetfluorescence exchange (numeric
// arrays, text, 1x1 structs, cell arrays) as a plain tree, read from and written to MAT 5 files
// (what MATLAB's save -v7 and Octave's save -v7 write; zlib-compressed when matio has zlib).
// Numeric arrays are kept column-major with their MATLAB dimensions, as MATLAB stores them.
// Every read error is an InputError naming the file and the variable path ("scene.data.photons").
#pragma once
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ofl {

struct MatValue {
  // Declared here, defaulted in mat_file.cpp: with an implicit constructor clang (with libstdc++)
  // cannot decide whether std::pair<std::string, MatValue> is default-constructible while
  // MatValue is still incomplete, and the recursive `fields` member fails to compile.
  MatValue();
  enum class Kind { kEmpty, kNumeric, kText, kStruct, kCell, kUnsupported };
  Kind kind = Kind::kEmpty;
  std::vector<size_t> dims = {0, 0};  // MATLAB dimensions (at least two)
  std::vector<double> numbers;        // numeric and logical data, column-major
  bool single = false;                // stored as single precision (MATLAB 'single')
  std::string text;                   // char arrays (rows concatenated)
  std::vector<std::pair<std::string, MatValue>> fields;  // 1x1 struct, in file order
  std::vector<MatValue> cells;        // cell array, column-major
  std::string unsupported;            // what a kUnsupported value was (complex, sparse, object, struct array)

  static MatValue scalar(double v);
  // A row (1 x n) or column (n x 1) vector.
  static MatValue vector(std::vector<double> v, bool column = false);
  static MatValue array(std::vector<size_t> dims, std::vector<double> column_major, bool single = false);
  static MatValue string(std::string s);
  static MatValue structure();
  static MatValue cell_row(std::vector<MatValue> cells);

  size_t numel() const;
  // Adds a field to a struct (replacing one of the same name); returns *this for chaining.
  MatValue& set(const std::string& name, MatValue v);
  const MatValue* field(const std::string& name) const;
  MatValue* field(const std::string& name);
};

using MatVariables = std::vector<std::pair<std::string, MatValue>>;

// Every variable of a .mat file (v4, v5 or, when matio was built with HDF5, v7.3).
MatVariables read_mat_file(const std::filesystem::path& file);
// Variable `name`, or nullopt when the file has no such variable.
std::optional<MatValue> read_mat_variable(const std::filesystem::path& file, const std::string& name);
// Writes a MAT 5 file (through a temporary name, renamed on success).
void write_mat_file(const std::filesystem::path& file, const MatVariables& vars);

// True when the file name ends in .mat (any case): the hook that lets a .mat stand where a CSV is read.
bool is_mat_file(const std::filesystem::path& file);

// Navigation with errors naming the file and the variable path, e.g.
// mat_require(file, sensor, "sensor", "pixel.width") -> the field or InputError(file, "sensor.pixel.width", ...).
const MatValue& mat_require(const std::string& file, const MatValue& root, const std::string& root_name,
                            const std::string& path);
const MatValue* mat_find(const MatValue& root, const std::string& path);
// A real finite scalar, or InputError naming `where`.
double mat_scalar(const std::string& file, const MatValue& v, const std::string& where);
// Numeric data as a vector (any shape), every value finite, or InputError naming `where`.
std::vector<double> mat_numbers(const std::string& file, const MatValue& v, const std::string& where);

}  // namespace ofl
