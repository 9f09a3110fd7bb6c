// A read-only view into a parsed JSON document that knows its file and its JSON pointer
// (e.g. "/lights/2/axis"), so every validation error names both. All scene, camera, sweep and
// model files are read through it.
#pragma once
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "renderer/core/errors/error.h"

namespace ofl {

class JsonNode {
 public:
  JsonNode(const nlohmann::json* j, std::string file, std::string path)
      : j_(j), file_(std::move(file)), path_(std::move(path)) {}

  const nlohmann::json& raw() const { return *j_; }
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_.empty() ? root_ : path_; }

  bool has(const std::string& key) const;
  JsonNode at(const std::string& key) const;  // required member
  std::optional<JsonNode> find(const std::string& key) const;
  JsonNode at(size_t index) const;
  size_t size() const;  // array length (error if not an array)
  std::vector<std::string> keys() const;  // object keys (error if not an object)
  bool is_object() const { return j_->is_object(); }
  bool is_array() const { return j_->is_array(); }
  bool is_number() const { return j_->is_number(); }
  bool is_string() const { return j_->is_string(); }

  double number(double lo = -std::numeric_limits<double>::infinity(),
                double hi = std::numeric_limits<double>::infinity()) const;
  double positive() const;  // > 0
  int integer(int lo = std::numeric_limits<int>::min(), int hi = std::numeric_limits<int>::max()) const;
  bool boolean() const;
  std::string string() const;
  glm::dvec3 vec3() const;
  glm::dvec3 unit_vec3() const;  // normalised, error if zero length
  std::vector<double> numbers() const;

  // Optional members with defaults.
  double number_or(const std::string& key, double def,
                   double lo = -std::numeric_limits<double>::infinity(),
                   double hi = std::numeric_limits<double>::infinity()) const;
  int integer_or(const std::string& key, int def, int lo = std::numeric_limits<int>::min(),
                 int hi = std::numeric_limits<int>::max()) const;
  bool boolean_or(const std::string& key, bool def) const;
  std::string string_or(const std::string& key, const std::string& def) const;
  // One of `allowed`, or the default when absent.
  std::string choice_or(const std::string& key, const std::string& def,
                        std::initializer_list<const char*> allowed) const;

  // Unknown members are errors, so that a typo ("radious") does not silently use a default.
  void check_keys(std::initializer_list<const char*> allowed) const;
  // A file named in this document, resolved against the document's folder; must exist.
  std::filesystem::path existing_file() const;
  // Reads the file this node names with `read(path)`. An input error inside that file keeps its
  // own file and line and gains "(named by <this file> <pointer>)", so the one-line message shows
  // both the broken file and the entry that referred to it.
  template <class Read>
  auto read_file(Read&& read) const -> decltype(read(std::filesystem::path())) {
    const std::filesystem::path p = existing_file();
    try {
      return read(p);
    } catch (const InputError& e) {
      if (e.file().empty() || e.file() == file_) throw;
      throw InputError(e.file(), e.field(), std::string(e.what()) + " (named by " + file_ + " " + path() + ")");
    }
  }

  [[noreturn]] void fail(const std::string& what) const;

 private:
  const nlohmann::json* j_;
  std::string file_, path_;
  static inline const std::string root_ = "/";
};

// Parses JSON text (comments allowed) read from `file`. Malformed text and values no double can
// hold ("1e999") are InputErrors naming the file and "line L column C".
nlohmann::json parse_json_text(const std::string& text, const std::string& file);

// A parsed JSON file that owns its document; root() gives the node for "/".
class JsonFile {
 public:
  // Throws InputError naming the file and line/column for a missing file or malformed JSON.
  static JsonFile load(const std::filesystem::path& file);
  static JsonFile from(nlohmann::json doc, std::string name);
  JsonNode root() const { return JsonNode(doc_.get(), name_, ""); }
  const nlohmann::json& doc() const { return *doc_; }
  const std::string& name() const { return name_; }

 private:
  std::shared_ptr<nlohmann::json> doc_;
  std::string name_;
};

}  // namespace ofl
