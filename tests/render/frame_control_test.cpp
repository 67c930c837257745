// The frame-time controller against synthetic cost models with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "pointillist/core/error.hpp"
#include "pointillist/render/frame_control.hpp"

using namespace pointillist;

namespace {

// Frame time of a splat renderer: fixed cost plus a cost per splat, splats ∝ threshold⁻².
double model_ms(double fixed, double per_unit, float threshold) {
  return fixed + per_unit / (double(threshold) * threshold);
}

// Deterministic noise in [-amplitude, amplitude] (relative).
double noise(std::uint32_t& state, double amplitude) {
  state = state * 1664525u + 1013904223u;
  return amplitude * (double(state >> 8) / double(1u << 24) * 2 - 1);
}

}  // namespace

TEST(FrameTimeController, ConvergesToTheThresholdThatHitsTheTargetWithoutOscillating) {
  // 2 ms fixed + 40 ms at 1 px: the 10 ms target needs threshold sqrt(40 / 8) = 2.236.
  FrameTimeController c({.target_ms = 10}, 1.0f);
  std::vector<float> p;
  for (int frame = 0; frame < 40; ++frame) {
    p.push_back(c.parameter());
    c.report(model_ms(2, 40, c.parameter()));
  }
  for (int frame = 12; frame < 40; ++frame) {
    EXPECT_NEAR(model_ms(2, 40, p[frame]), 10.0, 10.0 * 0.08 + 1e-9) << "frame " << frame;
  }
  // Settled: once inside the deadband the threshold no longer moves at all.
  for (int frame = 20; frame < 40; ++frame) EXPECT_EQ(p[frame], p[19]) << "frame " << frame;
  // Approached from one side (gain < 1): the sequence never goes back the way it came.
  for (int frame = 1; frame < 40; ++frame) EXPECT_GE(p[frame], p[frame - 1]) << "frame " << frame;
}

TEST(FrameTimeController, NoisyFramesStayWithinTwentyPercent) {
  FrameTimeController c({.target_ms = 16}, 8.0f);
  std::uint32_t state = 7;
  int hits = 0, counted = 0, reversals = 0;
  double last_step = 0;
  for (int frame = 0; frame < 300; ++frame) {
    const float before = c.parameter();
    const double ms = model_ms(3, 120, before) * (1 + noise(state, 0.10));
    if (frame >= 10) {
      ++counted;
      hits += std::abs(ms / 16 - 1) <= 0.2;
    }
    c.report(ms);
    const double step = double(c.parameter()) - before;
    if (step != 0) {
      reversals += (step > 0) != (last_step > 0) && last_step != 0;
      last_step = step;
    }
  }
  EXPECT_GE(hits, counted * 9 / 10);
  // ±10% noise against an 8% deadband: some corrections, but no sustained back and forth.
  EXPECT_LT(reversals, 60);
}

TEST(FrameTimeController, ReconvergesAfterTheSceneGetsHeavier) {
  FrameTimeController c({.target_ms = 10}, 2.0f);
  for (int frame = 0; frame < 30; ++frame) c.report(model_ms(1, 20, c.parameter()));
  EXPECT_NEAR(model_ms(1, 20, c.parameter()), 10, 0.8);
  // Three times as many splats (the camera turned toward the dense part of the model).
  for (int frame = 0; frame < 10; ++frame) c.report(model_ms(1, 60, c.parameter()));
  EXPECT_NEAR(model_ms(1, 60, c.parameter()), 10, 0.8);
  // sqrt(60 / 9) = 2.58 px.
  EXPECT_NEAR(c.parameter(), 2.58f, 0.12f);
}

TEST(FrameTimeController, CrossesARangeWhereTheParameterChangesNothing) {
  // Splats of 2.5 px: thresholds below that draw the same splats (flat cost), above it the cost
  // falls as p⁻². 3 ms fixed + 12 ms of splats; the 7 ms target needs p = 2.5·sqrt(12 / 4) = 4.33.
  auto cost = [](float p) { return 3.0 + 12.0 * std::min(1.0, 6.25 / (double(p) * p)); };
  FrameTimeController c({.target_ms = 7}, 1.0f);
  int frames = 0;
  while (std::abs(cost(c.parameter()) / 7 - 1) > 0.2 && frames < 100) {
    c.report(cost(c.parameter()));
    ++frames;
  }
  EXPECT_LE(frames, 10);
  for (int frame = 0; frame < 20; ++frame) c.report(cost(c.parameter()));
  EXPECT_NEAR(cost(c.parameter()), 7.0, 7.0 * 0.1);
}

TEST(FrameTimeController, FullDetailFasterThanTheTargetStaysAtFullDetail) {
  FrameTimeController c({.target_ms = 100}, 4.0f);
  for (int frame = 0; frame < 30; ++frame) c.report(model_ms(1, 10, c.parameter()));
  EXPECT_TRUE(c.at_full_detail());
  EXPECT_EQ(c.parameter(), 1.0f);
}

TEST(FrameTimeController, UnreachableTargetStopsAtTheCoarsestLevel) {
  FrameTimeController c({.target_ms = 1, .coarsest = 16}, 1.0f);
  for (int frame = 0; frame < 30; ++frame) c.report(model_ms(5, 100, c.parameter()));
  EXPECT_EQ(c.parameter(), 16.0f);
}

TEST(FrameTimeController, OneSlowFrameMovesTheThresholdAtMostMaxStep) {
  FrameTimeController c({.target_ms = 10, .max_step = 1.5}, 2.0f);
  c.report(1000.0);
  EXPECT_FLOAT_EQ(c.parameter(), 3.0f);
  c.report(std::nan(""));  // ignored
  c.report(-1.0);          // ignored
  EXPECT_FLOAT_EQ(c.parameter(), 3.0f);
}

TEST(FrameTimeController, AnIsolatedSpikeBarelyMovesTheThreshold) {
  // Cost model ms = 40·p^-2 (target 10 ms at p = 2). On target, then one frame 50% slow at the
  // same p: a gain of 0.7 would coarsen p by 1.5^(0.7/2) = +15% and make the next normal frame
  // 25% fast (a miss); with the spike gain 0.2, p moves by 1.5^(0.2/2) = +4.1%, and the next
  // normal frame (8% fast) is within the deadband, so p stays.
  FrameTimeController c({.target_ms = 10}, 2.0f);
  const auto cost = [](float p) { return 40.0 / (double(p) * p); };
  c.report(cost(c.parameter()));
  EXPECT_FLOAT_EQ(c.parameter(), 2.0f);
  c.report(1.5 * cost(c.parameter()));
  EXPECT_NEAR(c.parameter(), 2.0 * std::pow(1.5, 0.1), 1e-4);
  const float after = c.parameter();
  c.report(cost(after));
  EXPECT_FLOAT_EQ(c.parameter(), after);
  EXPECT_NEAR(cost(after), 10.0, 1.0);
  EXPECT_THROW(FrameTimeController({.target_ms = 10, .spike_ratio = 1.0}, 1.0f), OptionError);
  EXPECT_THROW(FrameTimeController({.target_ms = 10, .spike_gain = 0}, 1.0f), OptionError);
}

TEST(FrameTimeController, RejectsBadOptions) {
  EXPECT_THROW(FrameTimeController({.target_ms = 0}, 1.0f), OptionError);
  EXPECT_THROW(FrameTimeController({.target_ms = 10, .finest = 0}, 1.0f), OptionError);
  EXPECT_THROW(FrameTimeController({.target_ms = 10, .finest = 4, .coarsest = 2}, 1.0f), OptionError);
  EXPECT_THROW(FrameTimeController({.target_ms = 10, .gain = 1.5}, 1.0f), OptionError);
  EXPECT_THROW(FrameTimeController({.target_ms = 10, .max_step = 1.0}, 1.0f), OptionError);
  EXPECT_THROW(FrameTimeController({.target_ms = 10}, std::nanf("")), OptionError);
}

TEST(RefinementSequence, GeometricStepsEndingExactlyAtFullDetail) {
  const std::vector<float> s = refinement_sequence(8.0f, 1.0f, 4);
  ASSERT_EQ(s.size(), 4u);
  EXPECT_FLOAT_EQ(s[0], 8.0f);
  EXPECT_FLOAT_EQ(s[1], 4.0f);
  EXPECT_FLOAT_EQ(s[2], 2.0f);
  EXPECT_EQ(s[3], 1.0f);
  EXPECT_EQ(refinement_sequence(0.5f, 1.0f, 3), (std::vector<float>{1, 1, 1}));
  EXPECT_EQ(refinement_sequence(6.0f, 1.0f, 1), (std::vector<float>{1}));
  EXPECT_THROW(refinement_sequence(4.0f, 1.0f, 0), OptionError);
}
