#include "renderer/formats/mat_file.h"

#include <matio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <memory>
#include <system_error>

#include "renderer/core/files/atomic_file.h"
#include "renderer/core/errors/error.h"
#include "renderer/formats/mat_prescan.h"

namespace ofl {

MatValue::MatValue() = default;

// ---- MatValue -------------------------------------------------------------------------------

MatValue MatValue::scalar(double v) { return array({1, 1}, {v}); }

MatValue MatValue::vector(std::vector<double> v, bool column) {
  size_t n = v.size();
  return array(column ? std::vector<size_t>{n, 1} : std::vector<size_t>{1, n}, std::move(v));
}

MatValue MatValue::array(std::vector<size_t> dims, std::vector<double> column_major, bool single) {
  MatValue m;
  m.kind = Kind::kNumeric;
  m.dims = std::move(dims);
  while (m.dims.size() < 2) m.dims.push_back(1);
  m.numbers = std::move(column_major);
  m.single = single;
  return m;
}

MatValue MatValue::string(std::string s) {
  MatValue m;
  m.kind = Kind::kText;
  m.dims = {s.empty() ? size_t(0) : size_t(1), s.size()};
  m.text = std::move(s);
  return m;
}

MatValue MatValue::structure() {
  MatValue m;
  m.kind = Kind::kStruct;
  m.dims = {1, 1};
  return m;
}

MatValue MatValue::cell_row(std::vector<MatValue> cells) {
  MatValue m;
  m.kind = Kind::kCell;
  m.dims = {1, cells.size()};
  m.cells = std::move(cells);
  return m;
}

size_t MatValue::numel() const {
  size_t n = 1;
  for (size_t d : dims) n *= d;
  return n;
}

MatValue& MatValue::set(const std::string& name, MatValue v) {
  for (auto& f : fields)
    if (f.first == name) {
      f.second = std::move(v);
      return *this;
    }
  fields.emplace_back(name, std::move(v));
  return *this;
}

const MatValue* MatValue::field(const std::string& name) const {
  for (auto& f : fields)
    if (f.first == name) return &f.second;
  return nullptr;
}

MatValue* MatValue::field(const std::string& name) {
  for (auto& f : fields)
    if (f.first == name) return &f.second;
  return nullptr;
}

bool is_mat_file(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".mat";
}

// ---- reading --------------------------------------------------------------------------------

namespace {

constexpr int kMaxDepth = 32;
constexpr size_t kMaxElements = size_t(1) << 32;  // 4 G elements: far above any spectral image

struct MatCloser {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFreer {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using MatPtr = std::unique_ptr<mat_t, MatCloser>;
using VarPtr = std::unique_ptr<matvar_t, VarFreer>;

// matio reports problems through its logger (stderr by default); the caller reports them instead.
void quiet_matio() {
  static bool done = false;
  if (done) return;
  done = true;
  Mat_LogInitFunc("oralfluor", [](int, char*) {});
}

MatPtr open_for_reading(const std::filesystem::path& file) {
  quiet_matio();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw InputError(file.string(), "", "file not found");
  if (std::filesystem::file_size(file, ec) == 0) throw InputError(file.string(), "", "empty file: not a MATLAB .mat file");
  check_mat4_sizes(file);  // libmatio's MAT 4 probe allocates the name length it reads
  MatPtr mat(Mat_Open(file.string().c_str(), MAT_ACC_RDONLY));
  if (!mat) throw InputError(file.string(), "", "not a MATLAB .mat file (libmatio cannot open it)");
  if (Mat_GetVersion(mat.get()) == MAT_FT_MAT5) check_mat5_sizes(file);  // before libmatio trusts the dimensions
  return mat;
}

template <class T>
void append_numbers(const void* data, size_t n, std::vector<double>& out) {
  const T* p = static_cast<const T*>(data);
  out.reserve(n);
  for (size_t i = 0; i < n; ++i) out.push_back(static_cast<double>(p[i]));
}

// Bytes per stored element of `type` (0: not a plain numeric or character storage type).
size_t storage_size(matio_types type) {
  switch (type) {
    case MAT_T_INT8: case MAT_T_UINT8: case MAT_T_UTF8: return 1;
    case MAT_T_INT16: case MAT_T_UINT16: case MAT_T_UTF16: return 2;
    case MAT_T_INT32: case MAT_T_UINT32: case MAT_T_SINGLE: return 4;
    case MAT_T_INT64: case MAT_T_UINT64: case MAT_T_DOUBLE: return 8;
    default: return 0;
  }
}

// The variable's data holds at least `n` elements of its storage type. The dimensions come from
// the file and need not agree with the data that follows them (found by fuzz_mat: a char array
// whose dimensions exceed its data was read past the end of the buffer).
bool data_holds(const matvar_t* v, size_t n, size_t element) {
  return v->data && element > 0 && v->nbytes / element >= n;
}

bool read_numbers(const matvar_t* v, size_t n, std::vector<double>& out) {
  if (n == 0) return true;
  if (!data_holds(v, n, storage_size(v->data_type))) return false;
  switch (v->data_type) {
    case MAT_T_DOUBLE: append_numbers<double>(v->data, n, out); return true;
    case MAT_T_SINGLE: append_numbers<float>(v->data, n, out); return true;
    case MAT_T_INT8: append_numbers<int8_t>(v->data, n, out); return true;
    case MAT_T_UINT8: append_numbers<uint8_t>(v->data, n, out); return true;
    case MAT_T_INT16: append_numbers<int16_t>(v->data, n, out); return true;
    case MAT_T_UINT16: append_numbers<uint16_t>(v->data, n, out); return true;
    case MAT_T_INT32: append_numbers<int32_t>(v->data, n, out); return true;
    case MAT_T_UINT32: append_numbers<uint32_t>(v->data, n, out); return true;
    case MAT_T_INT64: append_numbers<int64_t>(v->data, n, out); return true;
    case MAT_T_UINT64: append_numbers<uint64_t>(v->data, n, out); return true;
    default: return false;
  }
}

std::string read_text(const matvar_t* v, size_t rows, size_t cols) {
  if (rows * cols == 0 || !v->data) return "";
  const size_t element = v->data_type == MAT_T_UINT16 || v->data_type == MAT_T_UTF16 || v->data_type == MAT_T_INT16 ? 2 : 1;
  if (!data_holds(v, rows * cols, element)) throw std::length_error("character data shorter than its dimensions");
  auto at = [&](size_t i) -> unsigned {
    switch (v->data_type) {
      case MAT_T_UINT16: case MAT_T_UTF16: case MAT_T_INT16: return static_cast<const uint16_t*>(v->data)[i];
      default: return static_cast<const uint8_t*>(v->data)[i];
    }
  };
  std::string s;
  for (size_t r = 0; r < rows; ++r) {
    if (r > 0) s += '\n';
    for (size_t c = 0; c < cols; ++c) {
      unsigned ch = at(c * rows + r);
      s += ch < 128 ? char(ch) : '?';
    }
  }
  return s;
}

MatValue unsupported(const std::string& what) {
  MatValue m;
  m.kind = MatValue::Kind::kUnsupported;
  m.unsupported = what;
  return m;
}

MatValue convert(matvar_t* v, int depth) {
  MatValue m;
  if (!v) return m;  // an empty struct field
  if (depth > kMaxDepth) return unsupported("nested deeper than " + std::to_string(kMaxDepth) + " levels");
  m.dims.assign(v->dims, v->dims + std::max(v->rank, 0));
  while (m.dims.size() < 2) m.dims.push_back(1);
  size_t n = 1;
  for (size_t d : m.dims) {
    if (d != 0 && n > kMaxElements / d) return unsupported("more than 2^32 elements");
    n *= d;
  }
  if (v->isComplex) return unsupported("a complex array");
  switch (v->class_type) {
    case MAT_C_EMPTY:
      m.kind = MatValue::Kind::kEmpty;
      return m;
    case MAT_C_CHAR:
      m.kind = MatValue::Kind::kText;
      try {
        m.text = read_text(v, m.dims[0], n / std::max<size_t>(m.dims[0], 1));
      } catch (const std::length_error& e) {
        return unsupported(std::string("a char array whose ") + e.what());
      }
      return m;
    case MAT_C_DOUBLE: case MAT_C_SINGLE: case MAT_C_INT8: case MAT_C_UINT8: case MAT_C_INT16:
    case MAT_C_UINT16: case MAT_C_INT32: case MAT_C_UINT32: case MAT_C_INT64: case MAT_C_UINT64:
      m.kind = MatValue::Kind::kNumeric;
      m.single = v->class_type == MAT_C_SINGLE;
      if (!read_numbers(v, n, m.numbers)) return unsupported("a numeric array of an unknown storage type, or with less data than its dimensions");
      return m;
    case MAT_C_STRUCT: {
      if (n != 1) return unsupported("a struct array of " + std::to_string(n) + " elements");
      m.kind = MatValue::Kind::kStruct;
      unsigned nf = Mat_VarGetNumberOfFields(v);
      char* const* names = Mat_VarGetStructFieldnames(v);
      for (unsigned i = 0; names && i < nf; ++i)
        m.fields.emplace_back(names[i], convert(Mat_VarGetStructFieldByName(v, names[i], 0), depth + 1));
      return m;
    }
    case MAT_C_CELL:
      m.kind = MatValue::Kind::kCell;
      for (size_t i = 0; i < n; ++i) m.cells.push_back(convert(Mat_VarGetCell(v, int(i)), depth + 1));
      return m;
    case MAT_C_SPARSE: return unsupported("a sparse matrix");
    case MAT_C_OBJECT: return unsupported("a MATLAB object");
    case MAT_C_FUNCTION: return unsupported("a function handle");
    default: return unsupported("an unsupported MATLAB class");
  }
}

}  // namespace

MatVariables read_mat_file(const std::filesystem::path& file) {
  MatPtr mat = open_for_reading(file);
  MatVariables out;
  while (VarPtr v{Mat_VarReadNext(mat.get())}) {
    if (!v->name) continue;
    out.emplace_back(v->name, convert(v.get(), 0));
  }
  return out;
}

std::optional<MatValue> read_mat_variable(const std::filesystem::path& file, const std::string& name) {
  MatPtr mat = open_for_reading(file);
  // Look through the directory first: Mat_VarRead of a missing name is not an error we can tell apart.
  bool found = false;
  while (VarPtr info{Mat_VarReadNextInfo(mat.get())})
    if (info->name && name == info->name) { found = true; break; }
  if (!found) return std::nullopt;
  VarPtr v{Mat_VarRead(mat.get(), name.c_str())};
  if (!v) throw InputError(file.string(), "variable \"" + name + "\"", "cannot be read (damaged file?)");
  return convert(v.get(), 0);
}

// ---- writing --------------------------------------------------------------------------------

namespace {

matvar_t* to_matvar(const char* name, const MatValue& m, const std::string& where) {
  std::vector<size_t> dims = m.dims;
  while (dims.size() < 2) dims.push_back(1);
  const int rank = int(dims.size());
  switch (m.kind) {
    case MatValue::Kind::kEmpty: {
      size_t d[2] = {0, 0};
      return Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, d, nullptr, 0);
    }
    case MatValue::Kind::kNumeric: {
      if (m.numel() != m.numbers.size())
        throw std::logic_error("write_mat_file: " + where + " has " + std::to_string(m.numbers.size()) +
                               " values for its dimensions");
      if (m.single) {
        std::vector<float> f(m.numbers.begin(), m.numbers.end());
        return Mat_VarCreate(name, MAT_C_SINGLE, MAT_T_SINGLE, rank, dims.data(), f.empty() ? nullptr : f.data(), 0);
      }
      std::vector<double> d = m.numbers;
      return Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, rank, dims.data(), d.empty() ? nullptr : d.data(), 0);
    }
    case MatValue::Kind::kText: {
      // As MATLAB stores text: 16-bit code units (matio writes 8-bit char data with a wrong size).
      std::vector<uint16_t> u(m.text.begin(), m.text.end());
      for (auto& c : u) c &= 0xff;
      size_t d[2] = {u.empty() ? size_t(0) : size_t(1), u.size()};
      return Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, d, u.empty() ? nullptr : u.data(), 0);
    }
    case MatValue::Kind::kStruct: {
      std::vector<const char*> names;
      for (auto& f : m.fields) names.push_back(f.first.c_str());
      size_t d[2] = {1, 1};
      matvar_t* s = Mat_VarCreateStruct(name, 2, d, names.empty() ? nullptr : names.data(), unsigned(names.size()));
      if (!s) return nullptr;
      for (auto& f : m.fields) {
        matvar_t* child = to_matvar(nullptr, f.second, where + "." + f.first);
        if (!child) {
          Mat_VarFree(s);
          return nullptr;
        }
        // Returns the field it replaces (none in a new struct).
        if (matvar_t* old = Mat_VarSetStructFieldByName(s, f.first.c_str(), 0, child)) Mat_VarFree(old);
      }
      return s;
    }
    case MatValue::Kind::kCell: {
      // The cell owns its children: matio copies the pointer array and frees them with the cell.
      std::vector<matvar_t*> children;
      for (size_t i = 0; i < m.cells.size(); ++i) {
        matvar_t* child = to_matvar(nullptr, m.cells[i], where + "{" + std::to_string(i + 1) + "}");
        if (!child) {
          for (matvar_t* c : children) Mat_VarFree(c);
          return nullptr;
        }
        children.push_back(child);
      }
      return Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, rank, dims.data(), children.empty() ? nullptr : children.data(), 0);
    }
    case MatValue::Kind::kUnsupported: break;
  }
  throw std::logic_error("write_mat_file: " + where + " is " + m.unsupported + " and cannot be written");
}

}  // namespace

namespace {

bool same_number(double written, double read, bool single) {
  if (single) written = double(float(written));
  return written == read || (std::isnan(written) && std::isnan(read));
}

// True when `read` (from the file) holds what `written` asked for: kind, dimensions and every value.
// An empty value may come back as any empty kind (MATLAB has no separate empty type).
bool same_value(const MatValue& written, const MatValue& read) {
  const bool w_empty = written.kind == MatValue::Kind::kEmpty || (written.numel() == 0 && written.kind != MatValue::Kind::kStruct);
  if (w_empty) return read.numel() == 0 && read.kind != MatValue::Kind::kStruct;
  if (written.kind != read.kind) return false;
  switch (written.kind) {
    case MatValue::Kind::kNumeric: {
      std::vector<size_t> d = written.dims;
      while (d.size() < 2) d.push_back(1);
      if (d != read.dims || written.numbers.size() != read.numbers.size()) return false;
      for (size_t i = 0; i < read.numbers.size(); ++i)
        if (!same_number(written.numbers[i], read.numbers[i], written.single)) return false;
      return true;
    }
    case MatValue::Kind::kText: {
      std::string t = written.text;
      for (char& c : t)
        if ((unsigned char)c >= 128) c = '?';  // stored as 8-bit code units, read back as ASCII
      return t == read.text;
    }
    case MatValue::Kind::kStruct:
      if (written.fields.size() != read.fields.size()) return false;
      for (size_t i = 0; i < written.fields.size(); ++i)
        if (written.fields[i].first != read.fields[i].first || !same_value(written.fields[i].second, read.fields[i].second))
          return false;
      return true;
    case MatValue::Kind::kCell:
      if (written.cells.size() != read.cells.size()) return false;
      for (size_t i = 0; i < written.cells.size(); ++i)
        if (!same_value(written.cells[i], read.cells[i])) return false;
      return true;
    default: return false;
  }
}

}  // namespace

void write_mat_file(const std::filesystem::path& file, const MatVariables& vars) {
  quiet_matio();
  // libmatio writes by file name and does not report every failed write (a full disk left a cut
  // file and a zero return): it writes an in-memory file, which is read back whole (data included)
  // and compared with what was asked for, and only then do its bytes go to `file` through the
  // checked, atomic path (write_via_memory_file).
  write_via_memory_file(file, [&](const std::filesystem::path& name) {
    auto fail = [&](const std::string& what) { throw InputError(file.string(), "", what); };
    MatPtr mat(Mat_CreateVer(name.string().c_str(), "oralfluor", MAT_FT_MAT5));
    if (!mat) fail("cannot create the file (missing folder or no permission?)");
    for (auto& [var, value] : vars) {
      VarPtr v{to_matvar(var.c_str(), value, var)};
      if (!v) fail("libmatio cannot build variable \"" + var + "\"");
      if (Mat_VarWrite(mat.get(), v.get(), MAT_COMPRESSION_ZLIB) != 0) fail("cannot write variable \"" + var + "\"");
    }
    if (Mat_Close(mat.release()) != 0) fail("cannot write: libmatio could not close the file");
    MatVariables back;
    try {
      back = read_mat_file(name);
    } catch (const InputError& e) {
      fail(std::string("cannot write: libmatio's output does not read back (") + e.what() + ")" + file_size_limit_note());
    }
    if (back.size() != vars.size())
      fail("cannot write: " + std::to_string(back.size()) + " of " + std::to_string(vars.size()) +
           " variables of libmatio's output read back" + file_size_limit_note());
    for (size_t i = 0; i < vars.size(); ++i)
      if (back[i].first != vars[i].first || !same_value(vars[i].second, back[i].second))
        fail("cannot write: variable \"" + vars[i].first + "\" of libmatio's output does not read back as written" +
             file_size_limit_note());
  });
}

// ---- navigation -----------------------------------------------------------------------------

const MatValue* mat_find(const MatValue& root, const std::string& path) {
  const MatValue* v = &root;
  size_t start = 0;
  while (start <= path.size() && !path.empty()) {
    size_t dot = path.find('.', start);
    std::string part = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (v->kind != MatValue::Kind::kStruct) return nullptr;
    v = v->field(part);
    if (!v) return nullptr;
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return v;
}

const MatValue& mat_require(const std::string& file, const MatValue& root, const std::string& root_name,
                            const std::string& path) {
  const MatValue* v = mat_find(root, path);
  if (!v) throw InputError(file, root_name + "." + path, "missing field");
  return *v;
}

std::vector<double> mat_numbers(const std::string& file, const MatValue& v, const std::string& where) {
  if (v.kind == MatValue::Kind::kUnsupported) throw InputError(file, where, "is " + v.unsupported + ", expected numbers");
  if (v.kind != MatValue::Kind::kNumeric) throw InputError(file, where, "expected a numeric array");
  for (size_t i = 0; i < v.numbers.size(); ++i)
    if (!std::isfinite(v.numbers[i]))
      throw InputError(file, where, "element " + std::to_string(i + 1) + " is NaN or infinite");
  return v.numbers;
}

double mat_scalar(const std::string& file, const MatValue& v, const std::string& where) {
  std::vector<double> n = mat_numbers(file, v, where);
  if (n.size() != 1) throw InputError(file, where, "expected a scalar, found " + std::to_string(n.size()) + " values");
  return n[0];
}

}  // namespace ofl
