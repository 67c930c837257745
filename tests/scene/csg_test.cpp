// The CSG test scenes: samples and the exact ray caster agree with each other and with the
// sizes of spec §4.2.
#include "pointillist/scene/csg.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "pointillist/core/error.hpp"

using namespace pointillist;

namespace {

TEST(CsgScenes, EverySampleIsWhereTheRayCasterFindsItsFace) {
  for (const std::string& id : csg_scene_ids()) {
    const CsgScene scene = csg_scene(id);
    for (SamplingMode mode : {SamplingMode::Jittered, SamplingMode::Random}) {
      const CsgSamples s = sample_csg(scene, mode, 5);
      ASSERT_FALSE(s.labels.empty()) << id;
      std::size_t wrong = 0;
      for (std::size_t i = 0; i < s.labels.size(); i += 7) {
        const Vec3f p = s.points.positions[i], n = s.points.normals[i];
        // A ray from just outside the surface back along the normal meets it right there.
        const auto hit = ray_cast_csg(scene, p + n * 1e-3f, -n);
        const bool ok = hit && std::fabs(hit->t - 1e-3f) < 1e-5f && hit->label == s.labels[i] &&
                        dot(hit->normal, n) > 0.9999f;
        wrong += !ok;
        EXPECT_TRUE(csg_face_contains(scene, s.labels[i], p)) << id << " sample " << i;
      }
      // Samples within 1e-3 of an edge may see the other face first.
      EXPECT_LE(wrong, s.labels.size() / 7 / 100 + 1) << id;
    }
  }
}

TEST(CsgScenes, JitteredSampleCountsMatchTheSpecification) {
  // N≈ of spec §4.2 (after trimming).
  const std::pair<const char*, double> expected[] = {
      {"T1", 15000}, {"T3", 13400}, {"T5", 19600}, {"T9", 20500}, {"T13", 20100}};
  for (const auto& [id, n] : expected) {
    const double got = static_cast<double>(sample_csg(csg_scene(id), SamplingMode::Jittered, 1).labels.size());
    EXPECT_NEAR(got / n, 1.0, 0.05) << id << ": " << got;
  }
}

TEST(CsgScenes, StepHasItsEightFacesAndNoInnerOnes) {
  const CsgScene step = csg_scene("T8");
  const CsgSamples s = sample_csg(step, SamplingMode::Jittered, 2);
  std::vector<std::size_t> per_label(step.label_count());
  for (std::uint32_t l : s.labels) ++per_label[l];
  std::size_t faces = 0;
  for (std::size_t c : per_label) faces += c > 0;
  // Lower box: −x, +x, −y, +y (half of it), −z, +z; upper box: −x, +x (the riser), +y, −z, +z;
  // its −y face lies on the lower box and is gone, as is the lower +y face's left half.
  EXPECT_EQ(faces, 11u);
  for (std::size_t i = 0; i < s.labels.size(); ++i) {
    ASSERT_FALSE(std::fabs(s.points.positions[i].y) < 1e-6f && s.points.positions[i].x < -1e-3f)
        << "a sample on the inner face y = 0";
  }
}

TEST(CsgScenes, DifferenceFlipsTheSubtractedNormals) {
  const CsgScene plate = csg_scene("T4");
  const CsgSamples s = sample_csg(plate, SamplingMode::Jittered, 3);
  std::size_t wall = 0;
  for (std::size_t i = 0; i < s.labels.size(); ++i) {
    if (s.labels[i] != plate.first_label(1)) continue;  // the hole's wall
    ++wall;
    const Vec3f p = s.points.positions[i];
    EXPECT_NEAR(std::hypot(p.x, p.z), 0.5f, 1e-5f);
    EXPECT_LT(dot(s.points.normals[i], Vec3f{p.x, 0, p.z}), 0.0f);  // toward the axis
    EXPECT_LE(std::fabs(p.y), 0.2f + 1e-5f);
  }
  EXPECT_GT(wall, 600u);
}

TEST(CsgScenes, UnknownIdIsRefusedWithTheKnownOnes) {
  try {
    csg_scene("T99");
    FAIL();
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("T99"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("T13"), std::string::npos);
  }
}

}  // namespace

TEST(CsgSurfaceGroups, FacesOnOnePlaneAreOneSurface) {
  // The step is two boxes: their front faces (z = 1), back faces and left faces (x = -1) lie on
  // one plane each, so its 11 sampled faces make 8 surfaces (spec §4.5: T8 has 8 faces); the
  // cube's 6 faces stay 6; two spheres are 2.
  const std::pair<const char*, std::size_t> expected[] = {{"T8", 8}, {"T1", 6}, {"T9", 2}};
  for (const auto& [id, count] : expected) {
    const CsgScene scene = csg_scene(id);
    const CsgSamples s = sample_csg(scene, SamplingMode::Jittered, 1);
    const std::vector<std::uint32_t> group = csg_surface_groups(scene, s);
    ASSERT_EQ(group.size(), scene.label_count()) << id;
    std::set<std::uint32_t> distinct;  // surfaces with samples (the step's inner face has none)
    for (const std::uint32_t l : s.labels) distinct.insert(group[l]);
    EXPECT_EQ(distinct.size(), count) << id;
    // Samples of one group lie on one plane (planar faces) or one primitive's face.
    for (std::size_t i = 0; i < s.labels.size(); ++i) {
      for (std::size_t j = i + 1; j < s.labels.size(); j += 997) {
        if (group[s.labels[i]] != group[s.labels[j]] || s.labels[i] == s.labels[j]) continue;
        EXPECT_NEAR(dot(s.points.normals[i], s.points.normals[j]), 1.0f, 1e-4f) << id;
        EXPECT_NEAR(dot(s.points.normals[i], s.points.positions[i] - s.points.positions[j]), 0.0f,
                    1e-4f)
            << id;
      }
    }
  }
}
