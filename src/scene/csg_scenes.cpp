// The test scenes of specs/sharp-features.md §4.2 by id.
#include <cmath>
#include <string>

#include "csg_internal.hpp"
#include "pointillist/core/error.hpp"

namespace pointillist {
namespace {

Primitive box(Vec3f center, Vec3f half) {
  return {.kind = PrimitiveKind::Box, .center = center, .half = half};
}
Primitive sphere(Vec3f center, float radius) {
  return {.kind = PrimitiveKind::Sphere, .center = center, .radius = radius};
}
Primitive cylinder(Vec3f center, float radius, float half_length, int axis) {
  return {.kind = PrimitiveKind::Cylinder, .center = center, .radius = radius,
          .half_length = half_length, .axis = axis};
}
Primitive quad(Vec3f corner, Vec3f edge_u, Vec3f edge_v) {
  return {.kind = PrimitiveKind::Quad, .center = corner, .edge_u = edge_u, .edge_v = edge_v};
}

const int kWedgeAngles[] = {20, 30, 45, 60, 90, 120, 150, 165};

// T12: two 2 × 1 strips hinged on the z axis, symmetric about −y, so the hinge is a ridge on
// top: strip directions (±sin θ/2, −cos θ/2, 0), outward normals (±cos θ/2, sin θ/2, 0), whose
// dot product is −cos θ (at θ = 165° that is 0.966, above the default threshold 0.9).
void wedge(CsgScene& s, int degrees) {
  const float half = static_cast<float>(degrees) * kPi / 360.0f;
  const Vec3f a{std::sin(half), -std::cos(half), 0}, b{-std::sin(half), -std::cos(half), 0};
  const Vec3f hinge{0, 0, -1}, along{0, 0, 2};
  s.primitives = {quad(hinge, along, a), quad(hinge, b, along)};
  s.op = CsgOp::Separate;
  s.spacing = 0.03f;
}

}  // namespace

std::vector<std::string> csg_scene_ids() {
  std::vector<std::string> ids = {"T1", "T2", "T3", "T4", "T5", "T6", "T7", "T8", "T9", "T10", "T11"};
  for (const int a : kWedgeAngles) ids.push_back("T12-" + std::to_string(a));
  for (const char* id : {"T13", "T14-2", "T14-5", "T15"}) ids.push_back(id);
  return ids;
}

CsgScene csg_scene(const std::string& id) {
  CsgScene s;
  s.name = id;
  if (id == "T1" || id == "T2" || id == "T14" || id == "T14-2" || id == "T14-5") {
    s.primitives = {box({0, 0, 0}, {1, 1, 1})};
    s.spacing = 0.04f;
    if (id == "T2") s.primitives[0].face_spacing = {0.02f, 0.04f, 0.08f};
    if (id != "T1" && id != "T2") {
      s.normal_noise_degrees = id == "T14-5" ? 5.0f : 2.0f;
      s.position_noise = 0.1f;
    }
  } else if (id == "T3") {
    s.primitives = {cylinder({0, 0, 0}, 0.8f, 0.8f, 1)};
    s.spacing = 0.03f;
  } else if (id == "T4") {
    s.primitives = {box({0, 0, 0}, {1, 0.2f, 1}), cylinder({0, 0, 0}, 0.5f, 0.3f, 1)};
    s.op = CsgOp::Difference;
    s.spacing = 0.03f;
  } else if (id == "T5" || id == "T6" || id == "T9") {
    s.primitives = {sphere({-0.6f, 0, 0}, 1), sphere({0.6f, 0, 0}, 1)};
    s.op = id == "T5" ? CsgOp::Union : (id == "T6" ? CsgOp::Intersection : CsgOp::Separate);
    s.spacing = id == "T5" ? 0.032f : (id == "T6" ? 0.02f : 0.035f);
  } else if (id == "T7") {
    s.primitives = {box({0, 0, 0}, {1, 1, 1}), sphere({1, 1, 1}, 0.9f)};
    s.op = CsgOp::Difference;
    s.spacing = 0.04f;
  } else if (id == "T8") {
    s.primitives = {box({0, -0.5f, 0}, {1, 0.5f, 1}), box({-0.5f, 0.5f, 0}, {0.5f, 0.5f, 1})};
    s.spacing = 0.04f;
  } else if (id == "T10") {
    s.primitives = {cylinder({0, 0, 0}, 0.5f, 1.2f, 0), cylinder({0, 0, 0}, 0.35f, 1.2f, 2)};
    s.op = CsgOp::Separate;
    s.spacing = 0.03f;
  } else if (id == "T11") {
    s.primitives = {box({0, 0, 0}, {1, 1, 0.01f})};
    s.spacing = 0.04f;
  } else if (id == "T12") {
    wedge(s, 90);
  } else if (id.rfind("T12-", 0) == 0) {
    for (const int a : kWedgeAngles) {
      if (id == "T12-" + std::to_string(a)) wedge(s, a);
    }
  } else if (id == "T13") {
    s.primitives = {sphere({0, 0, 0}, 1)};
    s.spacing = 0.025f;
  } else if (id == "T15") {
    s.primitives = {Primitive{.kind = PrimitiveKind::Crease}};
    s.op = CsgOp::Separate;
    s.spacing = 0.03f;
  }
  if (s.primitives.empty()) {
    std::string known;
    for (const std::string& k : csg_scene_ids()) known += (known.empty() ? "" : ", ") + k;
    throw OptionError("unknown test scene '" + id + "' (known: " + known + ")");
  }
  return s;
}

}  // namespace pointillist
