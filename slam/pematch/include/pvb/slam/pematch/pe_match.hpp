#pragma once
// PE-match: mismatch removal with an improved particle swarm over samples of
// eight coarse matches, scored by the epipolar constraint (paper sec. 4,
// eqs. 1-11; parameters sec. 5.1.2 for image pairs, sec. 5.2.2 for SLAM).
//
// Input is a list of coarse matches as pixel pairs; both the pair matcher
// (ORB + ratio test) and the SLAM motion model's windowed projection
// matcher feed it.  Output is the best fundamental matrix found (gbest), or
// "no model", and the inlier mask over ALL coarse matches (step 8).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "pvb/slam/pematch/fundamental.hpp"

namespace pvb::slam {

/// Distance of a coarse match to a fundamental matrix, used by the fitness
/// (step 3c) and the final filter (step 8).
enum class EpipolarDistance {
  kPointLine,  ///< eq. 8: distance of p2 to the epipolar line F p1 in image 2 (the paper)
  kSampson,    ///< Sampson distance, first-order geometric error over both images (beyond the paper)
};

/// PE-match parameters.  Defaults are the paper's image-pair values (sec. 5.1.2).
struct PeMatchParams {
  int population = 20;            ///< particles
  int num_differences = 3;        ///< n in eq. 10: particle pairs averaged into D
  double crossover_prob = 0.5;    ///< L in eq. 11
  double c1 = 0.5;                ///< eq. 9 weight of the personal best
  double c2 = 0.5;                ///< eq. 9 weight of the global best
  double inertia = 0.5;           ///< eq. 9 inertia weight omega
  int num_fitness_samples = 100;  ///< j: coarse matches scored per fitness (step 3c)
  int stall_iterations = 8;       ///< stop when gbest's fitness has not improved this many iterations
  int max_iterations = 100;       ///< iteration cap
  double inlier_threshold_px = 3.0;  ///< eq. 8 distance threshold, pixels
  EpipolarDistance distance = EpipolarDistance::kPointLine;  ///< distance compared with the threshold
  /// Beyond the paper: refine gbest's F on all its inliers (IRLS on the
  /// Sampson distance) before the final filtering.
  bool refine = false;
  int refine_iterations = 5;      ///< IRLS passes when refine is on
  /// Eq. 11 selection: when true (default), the crossed-over trial replaces
  /// Pbest_i only if its fitness is not lower (DE selection); when false it
  /// replaces Pbest_i unconditionally, the literal reading of eq. 11.
  bool greedy_pbest = true;
  std::uint32_t seed = 1;         ///< RNG seed; a call is a pure function of (matches, params)

  /// Paper values for image pairs (sec. 5.1.2): j = 100, stop after 8.
  static PeMatchParams for_pairs() { return {}; }
  /// Paper values inside SLAM tracking (sec. 5.2.2): j = 50, stop after 6.
  static PeMatchParams for_slam() {
    PeMatchParams p;
    p.num_fitness_samples = 50;
    p.stall_iterations = 6;
    return p;
  }
};

/// Outcome of one PE-match call.
struct PeMatchResult {
  /// gbest's fundamental matrix (x2^T F x1 = 0, unit Frobenius norm); empty
  /// ("no model") with fewer than 8 matches or when every sample was
  /// degenerate (e.g. all points collinear).
  std::optional<Eigen::Matrix3d> F;
  std::vector<std::uint8_t> inlier_mask;  ///< per coarse match: 1 = kept (eq. 8 <= threshold)
  int num_inliers = 0;                    ///< kept matches
  int fitness = 0;                        ///< gbest fitness: inliers among the j sampled matches
  int iterations = 0;                     ///< PSO iterations run
  int evaluations = 0;                    ///< fitness evaluations (F solves)
};

/// Small fast seeded generator (xoshiro256**, Blackman & Vigna 2018),
/// seeded through splitmix64.  uniform() is in [0, 1).
class PeRng {
 public:
  void seed(std::uint64_t s) {
    for (auto& w : s_) {
      s += 0x9e3779b97f4a7c15ULL;
      std::uint64_t z = s;
      z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
      z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
      w = z ^ (z >> 31);
    }
  }
  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4] = {1, 2, 3, 4};
};

/// A particle: eight distinct indices into the coarse matches, stored as
/// reals (eq. 9 moves them continuously) and kept sorted ascending.
using ParticlePos = std::array<double, 8>;

/// Eq. 10 perturbation f(D) = Dimension / (1 + exp(-1 / (10 D))) - Dimension / 2.
/// The extracted text lost the signs; we read the exponent as negative so that
/// f falls from Dimension/2 at D = 0 to 0 as D grows, as Fig. 6 shows (f > 0,
/// decreasing in D).  Equivalently (Dimension/2) * tanh(1 / (20 D)).
/// D <= 0 gives Dimension / 2.
double pe_mutation_perturbation(double D, double dimension);

/// Eq. 10 difference degree D for index particles: the mean over the n
/// given pairs (a_k, b_k) of mean_d |a_k[d] - b_k[d]| / (N - 1), i.e. each
/// "q_r2 - q_r3" is normalised by its largest possible value, the search
/// range N - 1, so D is in [0, 1].  Positions are sorted, so component d is
/// the d-th smallest index of each particle.
double pe_difference_degree(const ParticlePos* const* a, const ParticlePos* const* b, int n, int num_matches);

/// Maps a continuous position back to eight distinct valid indices (our
/// choice, the paper leaves it open): round each component, wrap it into
/// [0, N-1] modulo N (the order of coarse matches carries no meaning, so the
/// index space is a ring and no end is favoured), then, in component order,
/// move a duplicate up by one (mod N) until it is free; finally sort
/// ascending, permuting `vel` (may be null) alongside so each velocity
/// component stays with its index.  Writes the integer positions back into
/// `pos` and the indices into `idx`.  Requires N >= 8.
void pe_repair_position(ParticlePos& pos, ParticlePos* vel, std::array<int, 8>& idx, int num_matches);

/// The PE-match solver.  Holds every buffer the search needs, so repeated
/// calls with no more matches than before allocate nothing.  One per thread.
class PeMatcher {
 public:
  explicit PeMatcher(const PeMatchParams& params = {}) : params_(params) {}

  const PeMatchParams& params() const { return params_; }
  PeMatchParams& params() { return params_; }

  /// Runs PE-match on `n` coarse matches and fills `out` (its mask buffer is
  /// reused).  Deterministic for given matches and params (seed included).
  void match(const PointMatch* matches, std::size_t n, PeMatchResult& out);

  /// Convenience overload returning a fresh result.
  PeMatchResult match(const std::vector<PointMatch>& matches) {
    PeMatchResult r;
    match(matches.data(), matches.size(), r);
    return r;
  }

 private:
  /// The global best: its fitness (-1: none yet), position and F.
  struct Best {
    int fit = -1;
    ParticlePos pos{};
    Eigen::Matrix3d F = Eigen::Matrix3d::Zero();
  };
  /// Hartley normalisation of all n matches and the j-sample of step 3(c).
  void prepare(const PointMatch* matches, std::size_t n);
  /// Step 2: the swarm at eight distinct random matches per particle.
  Best init_swarm(int pop, PeMatchResult& out);
  /// Step 5 (eq. 9) for every particle, then steps 3-4 on where it lands.
  void move_particles(int pop, Best& best, PeMatchResult& out);
  /// Step 6: mutation (eq. 10) and crossover (eq. 11) on every Pbest.
  void mutate_pbests(int pop, Best& best, PeMatchResult& out);
  /// Optional refinement of the best F, then step 8: the inlier mask.
  void filter_matches(const Eigen::Matrix3d& F_best, PeMatchResult& out) const;
  /// Fitness of the particle with indices idx (eq. 8 inliers among the j
  /// samples) and its F in pixels; -1 when the sample is degenerate.
  int evaluate(const std::array<int, 8>& idx, Eigen::Matrix3d& F);
  /// True when m is within the threshold of F under params_.distance.
  bool is_inlier(const Eigen::Matrix3d& F, const PointMatch& m) const;

  PeMatchParams params_;
  PeRng rng_;
  const PointMatch* matches_ = nullptr;
  std::size_t num_matches_ = 0;
  Normalization norm1_, norm2_;
  std::vector<Eigen::Vector2d> x1n_, x2n_;  ///< normalised coordinates of all matches
  std::vector<int> sample_;                 ///< the j matches scored by the fitness
  std::vector<PointMatch> sample_pts_;      ///< their pixels, contiguous
  std::vector<int> shuffle_;                ///< scratch for drawing the sample
  std::vector<ParticlePos> pos_, vel_, pbest_;
  std::vector<int> pbest_fit_;
  std::vector<Eigen::Matrix3d> pbest_F_;
  std::vector<ParticlePos> last_pos_;       ///< position last evaluated per particle
  std::vector<int> last_fit_;               ///< its fitness
  std::vector<Eigen::Matrix3d> last_F_;     ///< its F
  std::array<int, 8> idx_{};                ///< scratch: a repaired position's indices
};

}  // namespace pvb::slam
