#include "renderer/mesh/files/obj_reader.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>
#include <tuple>

#include <glm/geometric.hpp>

#include "renderer/core/errors/error.h"

namespace ofl {
namespace {

struct Corner {
  long v = 0, vt = -1, vn = -1;  // zero-based; -1 = absent
};

struct Face {
  std::vector<Corner> corners;
  size_t mesh = 0;  // index into the (group, material) list
};

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\0' || c == '\f' || c == '\v'; }

std::vector<std::string_view> split_tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    size_t j = i;
    while (j < line.size() && !is_space(line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

class Parser {
 public:
  Parser(std::string name) : name_(std::move(name)) {}
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(name_, "line " + std::to_string(line_), what);
  }
  void set_line(size_t l) { line_ = l; }

  double number(std::string_view tok, const char* what) const {
    double v = 0;
    const char* b = tok.data();
    const char* e = tok.data() + tok.size();
    if (!tok.empty() && *b == '+') ++b;
    auto [p, ec] = std::from_chars(b, e, v);
    if (ec != std::errc() || p != e || !std::isfinite(v))
      fail(std::string("expected a number for ") + what + ", found '" + printable(std::string(tok), 40) + "'");
    return v;
  }

  // An OBJ index (1-based, or negative = relative to the current count) -> zero-based.
  long index(std::string_view tok, size_t count, const char* what) const {
    long v = 0;
    auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (ec != std::errc() || p != tok.data() + tok.size())
      fail(std::string("expected an integer ") + what + " index, found '" + printable(std::string(tok), 40) + "'");
    long zero_based = v > 0 ? v - 1 : static_cast<long>(count) + v;
    if (v == 0 || zero_based < 0 || zero_based >= static_cast<long>(count))
      fail(std::string(what) + " index " + std::to_string(v) + " out of range (" + std::to_string(count) +
           " defined so far)");
    return zero_based;
  }

 private:
  std::string name_;
  size_t line_ = 0;
};

}  // namespace

std::vector<uint32_t> triangulate_polygon(const std::vector<glm::dvec3>& c) {
  const size_t n = c.size();
  std::vector<uint32_t> tris;
  if (n < 3) return tris;
  if (n == 3) return {0, 1, 2};
  // Newell normal and a 2D basis in the polygon's plane (u x v = normal: the polygon is CCW).
  glm::dvec3 nrm(0.0);
  for (size_t i = 0; i < n; ++i) nrm += glm::cross(c[i], c[(i + 1) % n]);
  double len = glm::length(nrm);
  if (!(len > 0)) {  // degenerate: fan
    for (uint32_t i = 1; i + 1 < n; ++i) tris.insert(tris.end(), {0u, i, i + 1});
    return tris;
  }
  nrm /= len;
  glm::dvec3 u = glm::normalize(std::abs(nrm.x) < 0.9 ? glm::cross(nrm, {1, 0, 0}) : glm::cross(nrm, {0, 1, 0}));
  glm::dvec3 v = glm::cross(nrm, u);
  std::vector<glm::dvec2> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = {glm::dot(c[i], u), glm::dot(c[i], v)};
  auto cross2 = [](glm::dvec2 a, glm::dvec2 b, glm::dvec2 q) {
    return (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
  };
  if (n == 4) {
    bool convex = true;
    for (size_t i = 0; i < 4; ++i) convex &= cross2(p[i], p[(i + 1) % 4], p[(i + 2) % 4]) > 0;
    if (convex) {
      if (glm::length(c[0] - c[2]) <= glm::length(c[1] - c[3])) return {0, 1, 2, 0, 2, 3};
      return {0, 1, 3, 1, 2, 3};
    }
  }
  // Ear clipping.
  std::vector<uint32_t> ring(n);
  for (uint32_t i = 0; i < n; ++i) ring[i] = i;
  size_t guard = 0;
  while (ring.size() > 3 && guard < 4 * n * n) {
    bool clipped = false;
    for (size_t k = 0; k < ring.size(); ++k, ++guard) {
      uint32_t a = ring[(k + ring.size() - 1) % ring.size()], b = ring[k], d = ring[(k + 1) % ring.size()];
      if (cross2(p[a], p[b], p[d]) <= 0) continue;  // reflex or flat corner
      bool inside = false;
      for (uint32_t q : ring) {
        if (q == a || q == b || q == d) continue;
        if (cross2(p[a], p[b], p[q]) >= 0 && cross2(p[b], p[d], p[q]) >= 0 && cross2(p[d], p[a], p[q]) >= 0) {
          inside = true;
          break;
        }
      }
      if (inside) continue;
      tris.insert(tris.end(), {a, b, d});
      ring.erase(ring.begin() + static_cast<long>(k));
      clipped = true;
      break;
    }
    if (!clipped) break;  // self-intersecting or numerically flat: fan the rest
  }
  for (size_t i = 1; i + 1 < ring.size(); ++i) tris.insert(tris.end(), {ring[0], ring[i], ring[i + 1]});
  return tris;
}

namespace {

// What the statements of an OBJ file hold, before triangulation.
struct ObjStatements {
  std::vector<glm::dvec3> pos, nrm;
  std::vector<glm::dvec2> tex;
  std::vector<Face> faces;
  std::vector<std::pair<std::string, std::string>> keys;  // (group, material) per mesh
  bool all_normals = true;
};

// One "f" statement's corners ("v", "v/vt", "v//vn", "v/vt/vn"), indices checked against what
// came before it.
Face parse_face(const std::vector<std::string_view>& tok, Parser& ps, ObjStatements& st) {
  if (tok.size() < 4) ps.fail("a face needs at least 3 corners");
  Face f;
  for (size_t i = 1; i < tok.size(); ++i) {
    std::string_view t = tok[i];
    Corner c;
    size_t s1 = t.find('/');
    c.v = ps.index(t.substr(0, s1), st.pos.size(), "vertex");
    if (s1 != std::string_view::npos) {
      std::string_view rest = t.substr(s1 + 1);
      size_t s2 = rest.find('/');
      std::string_view vt = rest.substr(0, s2);
      if (!vt.empty()) c.vt = ps.index(vt, st.tex.size(), "texture coordinate");
      if (s2 != std::string_view::npos) {
        std::string_view vn = rest.substr(s2 + 1);
        if (!vn.empty()) c.vn = ps.index(vn, st.nrm.size(), "normal");
      }
    }
    st.all_normals &= c.vn >= 0;
    f.corners.push_back(c);
  }
  return f;
}

// Every statement of the text, line by line; counts what it ignores and the polygons it will
// triangulate into `out`.
ObjStatements read_statements(const std::string& text, const std::string& name, ObjContents& out) {
  Parser ps(name);
  ObjStatements st;
  std::map<std::pair<std::string, std::string>, size_t> key_index;
  std::string group = "default", material;
  size_t line_no = 0, start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + start, end - start);
    ++line_no;
    start = end + 1;
    ps.set_line(line_no);
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    auto tok = split_tokens(line);
    if (tok.empty()) {
      if (end == text.size()) break;
      continue;
    }
    std::string_view kw = tok[0];
    if (kw == "v") {
      if (tok.size() < 4) ps.fail("a vertex needs x y z");
      st.pos.push_back({ps.number(tok[1], "x"), ps.number(tok[2], "y"), ps.number(tok[3], "z")});
    } else if (kw == "vt") {
      if (tok.size() < 2) ps.fail("a texture coordinate needs u [v]");
      st.tex.push_back({ps.number(tok[1], "u"), tok.size() > 2 ? ps.number(tok[2], "v") : 0.0});
    } else if (kw == "vn") {
      if (tok.size() < 4) ps.fail("a normal needs x y z");
      st.nrm.push_back({ps.number(tok[1], "x"), ps.number(tok[2], "y"), ps.number(tok[3], "z")});
    } else if (kw == "f") {
      Face f = parse_face(tok, ps, st);
      auto key = std::make_pair(group, material);
      auto [it, fresh] = key_index.emplace(key, st.keys.size());
      if (fresh) st.keys.push_back(key);
      f.mesh = it->second;
      if (f.corners.size() > 3) ++out.polygons_triangulated;
      st.faces.push_back(std::move(f));
    } else if (kw == "g" || kw == "o") {
      group = tok.size() > 1 ? std::string(tok[1]) : "default";
    } else if (kw == "usemtl") {
      material = tok.size() > 1 ? std::string(tok[1]) : "";
    } else {
      ++out.ignored_statements;
    }
    if (end == text.size()) break;
  }
  return st;
}

// Each face's triangles (corner indices), and the smooth normal per position index (the sum of
// the area-weighted normals of the triangles that use it) for files that give none.
void triangulate_faces(const ObjStatements& st, std::vector<std::vector<uint32_t>>& face_tris,
                       std::vector<glm::dvec3>& smooth) {
  face_tris.assign(st.faces.size(), {});
  smooth.assign(st.pos.size(), glm::dvec3(0.0));
  for (size_t fi = 0; fi < st.faces.size(); ++fi) {
    const auto& f = st.faces[fi];
    std::vector<glm::dvec3> corners;
    for (auto& c : f.corners) corners.push_back(st.pos[c.v]);
    face_tris[fi] = triangulate_polygon(corners);
    for (size_t t = 0; t + 2 < face_tris[fi].size(); t += 3) {
      const auto& a = f.corners[face_tris[fi][t]];
      const auto& b = f.corners[face_tris[fi][t + 1]];
      const auto& d = f.corners[face_tris[fi][t + 2]];
      glm::dvec3 n = glm::cross(st.pos[b.v] - st.pos[a.v], st.pos[d.v] - st.pos[a.v]);
      smooth[a.v] += n;
      smooth[b.v] += n;
      smooth[d.v] += n;
    }
  }
}

// One mesh per (group, material), welding corners with the same position index, UV value and
// normal.
void build_meshes(const ObjStatements& st, const std::vector<std::vector<uint32_t>>& face_tris,
                  const std::vector<glm::dvec3>& smooth, ObjContents& out) {
  out.meshes.resize(st.keys.size());
  std::vector<std::map<std::tuple<long, float, float, long>, uint32_t>> welds(st.keys.size());
  for (size_t k = 0; k < st.keys.size(); ++k) {
    out.meshes[k].name = st.keys[k].first;
    out.meshes[k].material = st.keys[k].second;
  }
  bool any_uv = !st.tex.empty();
  for (size_t fi = 0; fi < st.faces.size(); ++fi) {
    const auto& f = st.faces[fi];
    auto& m = out.meshes[f.mesh];
    auto& weld = welds[f.mesh];
    for (uint32_t ci : face_tris[fi]) {
      const Corner& c = f.corners[ci];
      glm::vec2 uv(0.0f);
      if (c.vt >= 0) uv = glm::vec2(static_cast<float>(st.tex[c.vt].x), static_cast<float>(1.0 - st.tex[c.vt].y));
      auto key = std::make_tuple(c.v, uv.x, uv.y, c.vn);
      auto [it, fresh] = weld.emplace(key, static_cast<uint32_t>(m.positions.size()));
      if (fresh) {
        m.positions.push_back(glm::vec3(st.pos[c.v]));
        glm::dvec3 n = c.vn >= 0 ? st.nrm[c.vn] : smooth[c.v];
        double len = glm::length(n);
        m.normals.push_back(len > 0 ? glm::vec3(n / len) : glm::vec3(0, 0, 1));
        if (any_uv) m.uvs.push_back(uv);
      }
      m.indices.push_back(it->second);
    }
  }
}

}  // namespace

ObjContents parse_obj(const std::string& text, const std::string& name) {
  ObjContents out;
  const ObjStatements st = read_statements(text, name, out);
  out.positions = st.pos.size();
  out.texcoords = st.tex.size();
  out.normals = st.nrm.size();
  out.faces = st.faces.size();
  out.had_normals = st.all_normals && !st.faces.empty();
  std::vector<std::vector<uint32_t>> face_tris;
  std::vector<glm::dvec3> smooth;
  triangulate_faces(st, face_tris, smooth);
  build_meshes(st, face_tris, smooth, out);
  return out;
}

ObjContents read_obj(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string(), "", "cannot open OBJ file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_obj(ss.str(), file.string());
}

}  // namespace ofl
