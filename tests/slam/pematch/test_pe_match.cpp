#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "pvb/slam/pematch/pe_match.hpp"
#include "synthetic.hpp"

#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
// Counts heap allocations made by this test binary (for the no-allocation test).
static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace pvb::slam {
namespace {

struct Score {
  double precision = 0, recall = 0;
};

Score score(const test::TwoViewData& d, const PeMatchResult& r) {
  int kept = 0, correct_kept = 0, correct = 0;
  for (size_t i = 0; i < d.matches.size(); ++i) {
    correct += d.is_inlier[i];
    kept += r.inlier_mask[i];
    correct_kept += r.inlier_mask[i] && d.is_inlier[i];
  }
  return {kept ? double(correct_kept) / kept : 0.0, correct ? double(correct_kept) / correct : 0.0};
}

TEST(PeMutation, PerturbationKnownValues) {
  // f(D) = 100 / (1 + exp(-1 / (10 D))) - 50 = 50 tanh(1 / (20 D)), by hand:
  EXPECT_NEAR(pe_mutation_perturbation(1.0, 100.0), 2.4979187478940, 1e-9);   // 50 tanh(0.05)
  EXPECT_NEAR(pe_mutation_perturbation(0.1, 100.0), 23.1058578630, 1e-8);     // 50 tanh(0.5)
  EXPECT_NEAR(pe_mutation_perturbation(0.05, 100.0), 38.0797077978, 1e-8);    // 50 tanh(1)
  EXPECT_DOUBLE_EQ(pe_mutation_perturbation(0.0, 100.0), 50.0);
  EXPECT_NEAR(pe_mutation_perturbation(1e-4, 100.0), 50.0, 1e-9);
  // decreasing in D (Fig. 6)
  EXPECT_GT(pe_mutation_perturbation(0.2, 100.0), pe_mutation_perturbation(0.3, 100.0));
}

TEST(PeMutation, DifferenceDegreeOfIndexParticles) {
  const ParticlePos a{0, 1, 2, 3, 4, 5, 6, 7};
  const ParticlePos b{10, 11, 12, 13, 14, 15, 16, 17};
  const ParticlePos c{0, 1, 2, 3, 4, 5, 6, 107};
  const ParticlePos* lhs[3] = {&a, &a, &a};
  const ParticlePos* rhs[3] = {&b, &a, &c};
  // N = 101: range 100.  |a - b| = 10 per component -> 0.1; |a - a| = 0;
  // |a - c| = 100 in one component -> 100 / (8 * 100) = 0.125.
  EXPECT_DOUBLE_EQ(pe_difference_degree(lhs, rhs, 1, 101), 0.1);
  EXPECT_DOUBLE_EQ(pe_difference_degree(lhs, rhs, 3, 101), (0.1 + 0.0 + 0.125) / 3);
}

TEST(PeMutation, RepairGivesDistinctSortedIndices) {
  ParticlePos p{3.4, 3.2, 2.6, 2.7, -1.0, 100.0, 7.0, 7.4};
  ParticlePos v{0, 1, 2, 3, 4, 5, 6, 7};
  std::array<int, 8> idx{};
  pe_repair_position(p, &v, idx, 10);
  // round: 3 3 3 3 -1 100 7 7; wrap mod 10: 3 3 3 3 9 0 7 7;
  // duplicates move up: 3 4 5 6 9 0 7 8; sorted: 0 3 4 5 6 7 8 9.
  const std::array<int, 8> expect{0, 3, 4, 5, 6, 7, 8, 9};
  EXPECT_EQ(idx, expect);
  for (int c = 0; c < 8; ++c) EXPECT_EQ(p[c], expect[c]);
  // velocities followed their components: index 0 came from component 5, 9 from 4
  EXPECT_EQ(v[0], 5);
  EXPECT_EQ(v[7], 4);
  EXPECT_EQ(v[1], 0);
}

TEST(PeMatch, RecoversFWithHalfOutliers) {
  for (unsigned data_seed = 1; data_seed <= 5; ++data_seed) {
    const auto d = test::make_two_view(300, 0.5, 0.5, data_seed);
    for (bool refine : {false, true}) {
      PeMatchParams p;
      p.seed = 100 + data_seed;
      p.refine = refine;
      PeMatcher pm(p);
      const PeMatchResult r = pm.match(d.matches);
      ASSERT_TRUE(r.F.has_value());
      const Score s = score(d, r);
      EXPECT_GE(s.precision, 0.95) << "data seed " << data_seed << " refine " << refine;
      EXPECT_GE(s.recall, 0.9) << "data seed " << data_seed << " refine " << refine;
      EXPECT_LE(r.iterations, p.max_iterations);
    }
  }
}

TEST(PeMatch, SlamParametersAlsoRecoverF) {
  // j = 50 and stop after 6 (sec. 5.2.2) make a single call weaker than with
  // the pair values: some seeds settle on an F that keeps only ~80 % of the
  // inliers.  Asserted: every call is precise, and recall is >= 0.9 on
  // average over ten fixed seeds.
  const auto d = test::make_two_view(150, 0.5, 0.5, 42);
  PeMatchParams p = PeMatchParams::for_slam();
  EXPECT_EQ(p.num_fitness_samples, 50);
  EXPECT_EQ(p.stall_iterations, 6);
  double recall_sum = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    p.seed = seed;
    PeMatcher pm(p);
    const Score s = score(d, pm.match(d.matches));
    EXPECT_GE(s.precision, 0.95) << "seed " << seed;
    std::printf("seed %u precision %.3f recall %.3f\n", seed, s.precision, s.recall);
    recall_sum += s.recall;
  }
  EXPECT_GE(recall_sum / 10, 0.9);
}

TEST(PeMatch, SampsonDistanceRecoversFAndFiltersByIt) {
  // With EpipolarDistance::kSampson the final mask is exactly "Sampson
  // distance to the returned F <= threshold", and the filter still separates
  // inliers from outliers (alone and with refinement, the tracking setting).
  double recall_sum[2] = {0, 0};  // [refine]
  for (unsigned data_seed = 1; data_seed <= 3; ++data_seed) {
    const auto d = test::make_two_view(300, 0.5, 0.5, data_seed);
    for (bool refine : {false, true}) {
      PeMatchParams p = PeMatchParams::for_slam();
      p.distance = EpipolarDistance::kSampson;
      p.inlier_threshold_px = 2.0;
      p.refine = refine;
      p.seed = 20 + data_seed;
      PeMatcher pm(p);
      const PeMatchResult r = pm.match(d.matches);
      ASSERT_TRUE(r.F.has_value());
      int kept = 0;
      for (std::size_t i = 0; i < d.matches.size(); ++i) {
        const bool in = sampson_distance_sq(*r.F, d.matches[i].p1, d.matches[i].p2) <= 4.0;
        EXPECT_EQ(r.inlier_mask[i], in ? 1 : 0) << i;
        kept += in;
      }
      EXPECT_EQ(r.num_inliers, kept);
      const Score s = score(d, r);
      std::printf("data seed %u refine %d precision %.3f recall %.3f\n", data_seed, refine, s.precision, s.recall);
      EXPECT_GE(s.precision, 0.95) << "data seed " << data_seed << " refine " << refine;
      recall_sum[refine] += s.recall;
    }
  }
  // With the SLAM search values a single call may settle on an F from a
  // poor sample (see SlamParametersAlsoRecoverF); refining it on all its
  // inliers is what restores recall.
  EXPECT_GE(recall_sum[0] / 3, 0.75);
  EXPECT_GE(recall_sum[1] / 3, 0.9);
  EXPECT_GT(recall_sum[1], recall_sum[0]);
}

TEST(PeMatch, SampsonAndPointLineDistancesKeepDifferentSets) {
  // The option must change the test applied: on the same data and seed the
  // two distances (same threshold) do not give the same mask.
  const auto d = test::make_two_view(300, 0.5, 1.5, 4);
  PeMatchParams p = PeMatchParams::for_slam();
  p.inlier_threshold_px = 1.0;
  p.seed = 3;
  PeMatcher line(p);
  p.distance = EpipolarDistance::kSampson;
  PeMatcher sampson(p);
  const PeMatchResult a = line.match(d.matches), b = sampson.match(d.matches);
  ASSERT_TRUE(a.F && b.F);
  EXPECT_NE(a.inlier_mask, b.inlier_mask);
}

TEST(PeMatch, SameSeedSameResult) {
  const auto d = test::make_two_view(200, 0.5, 0.5, 3);
  PeMatchParams p;
  p.seed = 9;
  PeMatcher a(p), b(p);
  const PeMatchResult ra = a.match(d.matches);
  const PeMatchResult rb = b.match(d.matches);
  const PeMatchResult ra2 = a.match(d.matches);  // reused object, same call
  ASSERT_TRUE(ra.F && rb.F && ra2.F);
  EXPECT_EQ(*ra.F, *rb.F);
  EXPECT_EQ(*ra.F, *ra2.F);
  EXPECT_EQ(ra.inlier_mask, rb.inlier_mask);
  EXPECT_EQ(ra.iterations, rb.iterations);
  EXPECT_EQ(ra.evaluations, ra2.evaluations);
}

TEST(PeMatch, FewerThanEightMatchesIsNoModel) {
  const auto d = test::make_two_view(7, 0.0, 0.0, 1);
  PeMatcher pm;
  const PeMatchResult r = pm.match(d.matches);
  EXPECT_FALSE(r.F.has_value());
  EXPECT_EQ(r.num_inliers, 0);
  EXPECT_EQ(r.inlier_mask.size(), 7u);
  EXPECT_FALSE(pm.match(std::vector<PointMatch>{}).F.has_value());
}

TEST(PeMatch, CollinearPointsAreNoModel) {
  std::vector<PointMatch> m;
  for (int i = 0; i < 60; ++i)
    m.push_back({{10.0 + 9 * i, 20.0 + 4 * i}, {30.0 + 8.5 * i, 5.0 + 5 * i}});
  PeMatcher pm;
  const PeMatchResult r = pm.match(m);
  EXPECT_FALSE(r.F.has_value());
  EXPECT_EQ(r.num_inliers, 0);
  EXPECT_GT(r.evaluations, 0);
}

TEST(PeMatch, RepeatedCallsDoNotAllocate) {
  const auto d = test::make_two_view(500, 0.5, 0.5, 5);
  PeMatchParams p;
  p.refine = true;
  PeMatcher pm(p);
  PeMatchResult r;
  const long start = g_allocations.load();
  pm.match(d.matches.data(), d.matches.size(), r);  // warm-up sizes the buffers
  const long before = g_allocations.load();
  EXPECT_GT(before - start, 0);  // the counter sees the warm-up's allocations
  pm.params().seed = 77;
  pm.match(d.matches.data(), d.matches.size(), r);
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(r.F.has_value());
}

}  // namespace
}  // namespace pvb::slam
