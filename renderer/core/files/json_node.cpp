#include "renderer/core/files/json_node.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "renderer/core/errors/error.h"
#include "renderer/core/files/file_dependencies.h"

namespace ofl {
namespace {
std::string escape_pointer_token(const std::string& k) {
  std::string out;
  for (char c : k) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}
const char* type_name(const nlohmann::json& j) { return j.type_name(); }
}  // namespace

void JsonNode::fail(const std::string& what) const { throw InputError(file_, path(), what); }

bool JsonNode::has(const std::string& key) const { return j_->is_object() && j_->contains(key); }

JsonNode JsonNode::at(const std::string& key) const {
  if (!j_->is_object()) fail(std::string("expected an object, found ") + type_name(*j_));
  auto it = j_->find(key);
  if (it == j_->end()) throw InputError(file_, path_ + "/" + escape_pointer_token(key), "missing required field");
  return JsonNode(&*it, file_, path_ + "/" + escape_pointer_token(key));
}

std::optional<JsonNode> JsonNode::find(const std::string& key) const {
  if (!j_->is_object()) fail(std::string("expected an object, found ") + type_name(*j_));
  auto it = j_->find(key);
  if (it == j_->end() || it->is_null()) return std::nullopt;
  return JsonNode(&*it, file_, path_ + "/" + escape_pointer_token(key));
}

JsonNode JsonNode::at(size_t index) const {
  if (!j_->is_array()) fail(std::string("expected an array, found ") + type_name(*j_));
  if (index >= j_->size()) fail("index " + std::to_string(index) + " out of range");
  return JsonNode(&(*j_)[index], file_, path_ + "/" + std::to_string(index));
}

size_t JsonNode::size() const {
  if (!j_->is_array()) fail(std::string("expected an array, found ") + type_name(*j_));
  return j_->size();
}

std::vector<std::string> JsonNode::keys() const {
  if (!j_->is_object()) fail(std::string("expected an object, found ") + type_name(*j_));
  std::vector<std::string> k;
  for (auto it = j_->begin(); it != j_->end(); ++it) k.push_back(it.key());
  return k;
}

double JsonNode::number(double lo, double hi) const {
  if (!j_->is_number()) fail(std::string("expected a number, found ") + type_name(*j_));
  double v = j_->get<double>();
  if (!std::isfinite(v)) fail("expected a finite number");
  if (v < lo || v > hi) {
    std::ostringstream s;
    s << "value " << v << " outside the allowed range [" << lo << ", " << hi << "]";
    fail(s.str());
  }
  return v;
}

double JsonNode::positive() const {
  double v = number();
  if (!(v > 0)) fail("expected a positive number, found " + std::to_string(v));
  return v;
}

int JsonNode::integer(int lo, int hi) const {
  if (!j_->is_number_integer()) fail(std::string("expected an integer, found ") + type_name(*j_));
  auto v = j_->get<long long>();
  if (v < lo || v > hi)
    fail("value " + std::to_string(v) + " outside the allowed range [" + std::to_string(lo) +
         ", " + std::to_string(hi) + "]");
  return static_cast<int>(v);
}

bool JsonNode::boolean() const {
  if (!j_->is_boolean()) fail(std::string("expected true or false, found ") + type_name(*j_));
  return j_->get<bool>();
}

std::string JsonNode::string() const {
  if (!j_->is_string()) fail(std::string("expected a string, found ") + type_name(*j_));
  return j_->get<std::string>();
}

std::vector<double> JsonNode::numbers() const {
  std::vector<double> out;
  size_t n = size();
  for (size_t i = 0; i < n; ++i) out.push_back(at(i).number());
  return out;
}

glm::dvec3 JsonNode::vec3() const {
  if (!j_->is_array() || j_->size() != 3) fail("expected an array of 3 numbers");
  return {at(0).number(), at(1).number(), at(2).number()};
}

glm::dvec3 JsonNode::unit_vec3() const {
  glm::dvec3 v = vec3();
  double len = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  if (!(len > 1e-12)) fail("direction has zero length");
  return v / len;
}

double JsonNode::number_or(const std::string& key, double def, double lo, double hi) const {
  auto n = find(key);
  return n ? n->number(lo, hi) : def;
}
int JsonNode::integer_or(const std::string& key, int def, int lo, int hi) const {
  auto n = find(key);
  return n ? n->integer(lo, hi) : def;
}
bool JsonNode::boolean_or(const std::string& key, bool def) const {
  auto n = find(key);
  return n ? n->boolean() : def;
}
std::string JsonNode::string_or(const std::string& key, const std::string& def) const {
  auto n = find(key);
  return n ? n->string() : def;
}
std::string JsonNode::choice_or(const std::string& key, const std::string& def,
                                std::initializer_list<const char*> allowed) const {
  auto n = find(key);
  if (!n) return def;
  std::string v = n->string();
  std::string list;
  for (const char* a : allowed) {
    if (v == a) return v;
    list += std::string(list.empty() ? "" : ", ") + a;
  }
  n->fail("unknown value \"" + v + "\" (expected one of: " + list + ")");
}

void JsonNode::check_keys(std::initializer_list<const char*> allowed) const {
  if (!j_->is_object()) fail(std::string("expected an object, found ") + type_name(*j_));
  for (auto it = j_->begin(); it != j_->end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok && !it.key().empty() && it.key()[0] != '_' && it.key() != "comment") {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      throw InputError(file_, path_ + "/" + escape_pointer_token(it.key()),
                       "unknown field (allowed here: " + list + ")");
    }
  }
}

std::filesystem::path JsonNode::existing_file() const {
  std::filesystem::path p = string();
  if (p.is_relative()) p = std::filesystem::path(file_).parent_path() / p;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) fail("file not found: " + p.string());
  note_file_dependency(p);
  return p;
}

namespace {

// Finds where a parse stopped: nlohmann reports number overflow (out_of_range 406, "1e999") without
// a position, but its SAX interface is told the byte offset. Used only after a failed parse.
struct ErrorPosition : nlohmann::json_sax<nlohmann::json> {
  size_t byte = 0;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception&) override {
    byte = position;
    return false;
  }
};

std::string line_column(const std::string& text, size_t byte) {
  size_t pos = std::min<size_t>(byte > 0 ? byte - 1 : 0, text.size());
  int line = 1, col = 1;
  for (size_t i = 0; i < pos; ++i) {
    if (text[i] == '\n') { ++line; col = 1; } else { ++col; }
  }
  return "line " + std::to_string(line) + " column " + std::to_string(col);
}

// nlohmann's message without its "[json.exception.x.n] " and "parse error at line L, column C: " prefixes.
std::string json_message(const std::string& what) {
  std::string msg = what;
  if (msg.rfind("[json.exception.", 0) == 0)
    if (auto close = msg.find("] "); close != std::string::npos) msg = msg.substr(close + 2);
  if (auto at = msg.find(", column "); at != std::string::npos)
    if (auto cut = msg.find(": ", at); cut != std::string::npos) msg = msg.substr(cut + 2);
  return printable(msg, 160);
}

}  // namespace

nlohmann::json parse_json_text(const std::string& text, const std::string& file) {
  try {
    return nlohmann::json::parse(text, nullptr, true, true);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(file, line_column(text, e.byte), "malformed JSON: " + json_message(e.what()));
  } catch (const nlohmann::json::exception& e) {
    // Number overflow ("1e999") and the like: valid syntax, a value no double can hold.
    ErrorPosition where;
    nlohmann::json::sax_parse(text, &where, nlohmann::json::input_format_t::json, true, true);
    throw InputError(file, line_column(text, where.byte), "unusable JSON value: " + json_message(e.what()));
  }
}

JsonFile JsonFile::load(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open file");
  note_file_dependency(file);
  std::stringstream ss;
  ss << in.rdbuf();
  JsonFile f;
  f.name_ = file.string();
  f.doc_ = std::make_shared<nlohmann::json>(parse_json_text(ss.str(), f.name_));
  return f;
}

JsonFile JsonFile::from(nlohmann::json doc, std::string name) {
  JsonFile f;
  f.doc_ = std::make_shared<nlohmann::json>(std::move(doc));
  f.name_ = std::move(name);
  return f;
}

}  // namespace ofl
