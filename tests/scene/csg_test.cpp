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
    CsgScene scene = csg_scene(id);
    scene.normal_noise_degrees = scene.position_noise = 0;  // T14: the samples before the noise
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
      {"T1", 15000}, {"T2", 26250}, {"T3", 13400}, {"T5", 19600}, {"T9", 20500},
      {"T12-45", 4400}, {"T13", 20100}, {"T14-2", 15000}};
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

TEST(CsgScenes, MixedDensityCubeHasEachFacesSpacing) {
  // T2: ±x at h = 0.02, ±y at 0.04, ±z at 0.08 on a cube of side 2: (2/h)² samples a face.
  const CsgSamples s = sample_csg(csg_scene("T2"), SamplingMode::Jittered, 4);
  std::vector<std::size_t> per_label(6);
  for (std::uint32_t l : s.labels) ++per_label[l];
  const std::size_t expected[6] = {10000, 10000, 2500, 2500, 625, 625};
  for (int l = 0; l < 6; ++l) EXPECT_EQ(per_label[l], expected[l]) << "face " << l;
}

TEST(CsgScenes, WedgeStripsMeetAtTheirDihedralAngle) {
  // T12-θ: two 2 × 1 strips on the hinge x = y = 0; the outward normals' dot product is −cos θ
  // and each strip's samples lie within 1 of the hinge, on its plane.
  for (const int degrees : {20, 90, 165}) {
    const CsgScene scene = csg_scene("T12-" + std::to_string(degrees));
    const CsgSamples s = sample_csg(scene, SamplingMode::Random, 6);
    Vec3f n[2] = {};
    for (std::size_t i = 0; i < s.labels.size(); ++i) {
      ASSERT_LT(s.labels[i], 2u);
      n[s.labels[i]] = s.points.normals[i];
      const Vec3f p = s.points.positions[i];
      EXPECT_LE(std::hypot(p.x, p.y), 1.0f + 1e-5f);
      EXPECT_LE(std::fabs(p.z), 1.0f + 1e-5f);
      EXPECT_NEAR(dot(s.points.normals[i], p), 0.0f, 1e-5f);  // the strip's plane holds the hinge
    }
    EXPECT_NEAR(dot(n[0], n[1]), -std::cos(degrees * kPi / 180), 1e-5f) << degrees;
    EXPECT_GT(n[0].y, 0.0f);  // a ridge: seen from above
  }
  EXPECT_EQ(csg_scene("T12").primitives[1].edge_u, csg_scene("T12-90").primitives[1].edge_u);
}

TEST(CsgScenes, OpenCreaseIsTheHeightFieldAndOneSided) {
  // T15: y = 0.5·|x|·max(0, 1 − z). Rays straight down hit it there, with the normal of that
  // function's graph; rays straight up see its back and pass.
  const CsgScene scene = csg_scene("T15");
  for (float x = -0.95f; x < 1.0f; x += 0.1f) {
    for (float z = 0.05f; z < 2.0f; z += 0.1f) {
      const float y = 0.5f * std::fabs(x) * std::max(0.0f, 1 - z);
      const auto hit = ray_cast_csg(scene, {x, 3, z}, {0, -1, 0});
      ASSERT_TRUE(hit) << x << " " << z;
      EXPECT_NEAR(3 - hit->t, y, 1e-5f);
      const std::uint32_t label = z >= 1 ? 2u : (x < 0 ? 0u : 1u);
      EXPECT_EQ(hit->label, label);
      // The graph's normal: (−∂y/∂x, 1, −∂y/∂z), normalised.
      const float dx = z < 1 ? 0.5f * (x < 0 ? -1 : 1) * (1 - z) : 0;
      const float dz = z < 1 ? -0.5f * std::fabs(x) : 0;
      const Vec3f expected = normalized(Vec3f{-dx, 1, -dz});
      EXPECT_GT(dot(hit->normal, expected), 0.99999f) << x << " " << z;
      EXPECT_FALSE(ray_cast_csg(scene, {x, -3, z}, {0, 1, 0}));
    }
  }
}

TEST(CsgScenes, NoisyCubeHasTheNoiseItNames) {
  // T14-2 and T14-5: T1's samples, each normal tilted by an angle of standard deviation 2° or 5°
  // and each position moved along its face's normal by 0.1 h (σ).
  const CsgSamples clean = sample_csg(csg_scene("T1"), SamplingMode::Jittered, 8);
  for (const float sigma : {2.0f, 5.0f}) {
    const CsgSamples noisy =
        sample_csg(csg_scene(sigma == 2.0f ? "T14-2" : "T14-5"), SamplingMode::Jittered, 8);
    ASSERT_EQ(noisy.labels, clean.labels);
    double angle2 = 0, offset2 = 0, tangential = 0;
    for (std::size_t i = 0; i < clean.labels.size(); ++i) {
      const Vec3f n = clean.points.normals[i];
      const double a = std::acos(std::min(1.0f, dot(n, noisy.points.normals[i])));
      angle2 += a * a;
      const Vec3f d = noisy.points.positions[i] - clean.points.positions[i];
      offset2 += double(dot(d, n)) * dot(d, n);
      tangential = std::max(tangential, double(length(d - n * dot(d, n))));
    }
    const double count = static_cast<double>(clean.labels.size());
    EXPECT_NEAR(std::sqrt(angle2 / count) * 180 / kPi, sigma, 0.05 * sigma);
    EXPECT_NEAR(std::sqrt(offset2 / count), 0.1 * 0.04, 0.05 * 0.1 * 0.04);
    EXPECT_LT(tangential, 1e-6);
  }
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
