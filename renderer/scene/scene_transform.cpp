#include "renderer/scene/scene_transform.h"

#include <glm/gtx/transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace ofl {

glm::dmat4 parse_transform(const JsonNode& n) {
  n.check_keys({"translate", "rotate_deg", "scale", "matrix"});
  if (auto m = n.find("matrix")) {
    if (n.has("translate") || n.has("rotate_deg") || n.has("scale")) n.fail("matrix excludes translate/rotate_deg/scale");
    auto v = m->numbers();
    if (v.size() != 16) m->fail("expected 16 numbers (column-major)");
    return glm::make_mat4(v.data());
  }
  glm::dmat4 t(1.0);
  if (auto s = n.find("scale")) {
    glm::dvec3 sc = s->is_number() ? glm::dvec3(s->positive()) : s->vec3();
    if (!(sc.x > 0 && sc.y > 0 && sc.z > 0)) s->fail("scale factors must be positive");
    t = glm::scale(sc) * t;
  }
  if (auto r = n.find("rotate_deg")) {
    glm::dvec3 a = glm::radians(r->vec3());
    t = glm::rotate(a.z, glm::dvec3(0, 0, 1)) * glm::rotate(a.y, glm::dvec3(0, 1, 0)) * glm::rotate(a.x, glm::dvec3(1, 0, 0)) * t;
  }
  if (auto tr = n.find("translate")) t = glm::translate(tr->vec3()) * t;
  return t;
}

}  // namespace ofl
