#include "pvb/slam/pematch/pe_match.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace pvb::slam {
namespace {

constexpr int kDim = 8;  ///< indices per particle (8-point algorithm)

/// Wraps an integer into [0, n).
inline int wrap_index(long long v, int n) {
  long long r = v % n;
  return static_cast<int>(r < 0 ? r + n : r);
}

}  // namespace

double pe_mutation_perturbation(double D, double dimension) {
  if (!(D > 0.0)) return 0.5 * dimension;
  return dimension / (1.0 + std::exp(-1.0 / (10.0 * D))) - 0.5 * dimension;
}

double pe_difference_degree(const ParticlePos* const* a, const ParticlePos* const* b, int n, int num_matches) {
  if (n <= 0 || num_matches <= 1) return 0.0;
  const double range = static_cast<double>(num_matches - 1);
  double sum = 0.0;
  for (int k = 0; k < n; ++k) {
    double d = 0.0;
    for (int c = 0; c < kDim; ++c) d += std::abs((*a[k])[c] - (*b[k])[c]);
    sum += d / (kDim * range);
  }
  return sum / n;
}

void pe_repair_position(ParticlePos& pos, ParticlePos* vel, std::array<int, 8>& idx, int num_matches) {
  assert(num_matches >= kDim);
  for (int c = 0; c < kDim; ++c) {
    const double r = std::floor(pos[c] + 0.5);  // round half up
    // Guard against non-finite or huge values before the integer cast.
    const long long v = std::isfinite(r) ? static_cast<long long>(std::clamp(r, -1e15, 1e15)) : 0;
    int k = wrap_index(v, num_matches);
    for (;;) {
      bool used = false;
      for (int e = 0; e < c; ++e) used |= (idx[e] == k);
      if (!used) break;
      k = (k + 1) % num_matches;
    }
    idx[c] = k;
  }
  // Sort indices ascending (insertion sort on 8 values), velocity alongside.
  for (int c = 1; c < kDim; ++c) {
    const int key = idx[c];
    const double vkey = vel ? (*vel)[c] : 0.0;
    int e = c - 1;
    while (e >= 0 && idx[e] > key) {
      idx[e + 1] = idx[e];
      if (vel) (*vel)[e + 1] = (*vel)[e];
      --e;
    }
    idx[e + 1] = key;
    if (vel) (*vel)[e + 1] = vkey;
  }
  for (int c = 0; c < kDim; ++c) pos[c] = idx[c];
}

bool PeMatcher::is_inlier(const Eigen::Matrix3d& F, const PointMatch& m) const {
  const double thr = params_.inlier_threshold_px;
  if (params_.distance == EpipolarDistance::kSampson) return sampson_distance_sq(F, m.p1, m.p2) <= thr * thr;
  return within_epipolar_threshold(F, m.p1, m.p2, thr);
}

int PeMatcher::evaluate(const std::array<int, 8>& idx, Eigen::Matrix3d& F) {
  Eigen::Matrix<double, 8, 2> a, b;
  for (int c = 0; c < kDim; ++c) {
    a.row(c) = x1n_[idx[c]].transpose();
    b.row(c) = x2n_[idx[c]].transpose();
  }
  Eigen::Matrix3d Fn;
  if (!solve_fundamental_8_normalized(a, b, Fn)) return -1;
  F.noalias() = norm2_.T.transpose() * Fn * norm1_.T;
  // Step 3(b)-(c): eq. 8 inliers among the j sampled coarse matches.
  int fit = 0;
  for (const PointMatch& m : sample_pts_) fit += is_inlier(F, m) ? 1 : 0;
  return fit;
}

void PeMatcher::prepare(const PointMatch* matches, std::size_t n) {
  const int N = static_cast<int>(n);
  matches_ = matches;
  num_matches_ = n;
  rng_.seed(params_.seed);
  // Hartley normalisation computed once over all coarse matches (our choice:
  // same conditioning as per-sample normalisation for the 8-point solve of
  // eq. 5, at a fraction of the cost).
  const std::size_t stride = sizeof(PointMatch) / sizeof(Eigen::Vector2d);
  norm1_ = hartley_normalization(&matches[0].p1, n, stride);
  norm2_ = hartley_normalization(&matches[0].p2, n, stride);
  x1n_.resize(n);
  x2n_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    x1n_[i] = norm1_.apply(matches[i].p1);
    x2n_[i] = norm2_.apply(matches[i].p2);
  }
  // Step 3(c): the j matches scored by the fitness.  Our choice: one sample
  // drawn per call (partial Fisher-Yates), so all particles are compared on
  // the same matches and "gbest unchanged" (step 7) is well defined.
  const int j = std::min(N, std::max(1, params_.num_fitness_samples));
  shuffle_.resize(n);
  for (int i = 0; i < N; ++i) shuffle_[i] = i;
  sample_.resize(j);
  for (int k = 0; k < j; ++k) {
    const int r = k + static_cast<int>(rng_.uniform() * (N - k));
    std::swap(shuffle_[k], shuffle_[std::min(r, N - 1)]);
    sample_[k] = shuffle_[k];
  }
  sample_pts_.resize(j);
  for (int k = 0; k < j; ++k) sample_pts_[k] = matches[sample_[k]];
}

PeMatcher::Best PeMatcher::init_swarm(int pop, PeMatchResult& out) {
  const int N = static_cast<int>(num_matches_);
  for (auto* v : {&pos_, &vel_, &pbest_, &last_pos_}) v->resize(pop);
  for (auto* v : {&pbest_fit_, &last_fit_}) v->resize(pop);
  for (auto* v : {&pbest_F_, &last_F_}) v->resize(pop);
  Best best;
  int gbest = -1;  // particle whose pbest is the global best
  for (int i = 0; i < pop; ++i) {
    for (int c = 0; c < kDim; ++c) {
      // Draw distinct indices by rejection (N >= 8, so this ends quickly).
      for (;;) {
        const int k = std::min(N - 1, static_cast<int>(rng_.uniform() * N));
        bool used = false;
        for (int e = 0; e < c; ++e) used |= (idx_[e] == k);
        if (!used) {
          idx_[c] = k;
          break;
        }
      }
      pos_[i][c] = idx_[c];
      vel_[i][c] = 0.0;
    }
    pe_repair_position(pos_[i], &vel_[i], idx_, N);  // sorts
    pbest_[i] = pos_[i];
    pbest_fit_[i] = evaluate(idx_, pbest_F_[i]);
    last_pos_[i] = pos_[i];
    last_fit_[i] = pbest_fit_[i];
    last_F_[i] = pbest_F_[i];
    ++out.evaluations;
    if (pbest_fit_[i] > best.fit) {
      best.fit = pbest_fit_[i];
      gbest = i;
    }
  }
  if (gbest >= 0) {
    best.pos = pbest_[gbest];
    best.F = pbest_F_[gbest];
  }
  return best;
}

void PeMatcher::move_particles(int pop, Best& best, PeMatchResult& out) {
  const PeMatchParams& P = params_;
  const int N = static_cast<int>(num_matches_);
  Eigen::Matrix3d F;
  for (int i = 0; i < pop; ++i) {
    // Step 5, eq. 9: V <- w V + c1 r4 (Pbest - X) + c2 r5 (Gbest - X),
    // X <- X + V (the new V; the text's "V_i(t)" is read as a typo).  r4, r5
    // are drawn per component.
    ParticlePos& x = pos_[i];
    ParticlePos& v = vel_[i];
    for (int c = 0; c < kDim; ++c) {
      const double r4 = rng_.uniform(), r5 = rng_.uniform();
      v[c] = P.inertia * v[c] + P.c1 * r4 * (pbest_[i][c] - x[c]) + P.c2 * r5 * (best.pos[c] - x[c]);
      x[c] += v[c];
    }
    pe_repair_position(x, &v, idx_, N);
    // Steps 3-4: fitness, Pbest and Gbest.  A particle that did not move
    // keeps its fitness (the j-sample is fixed per call): no re-solve.
    int fit;
    if (x == last_pos_[i]) {
      fit = last_fit_[i];
      F = last_F_[i];
    } else {
      fit = evaluate(idx_, F);
      ++out.evaluations;
      last_pos_[i] = x;
      last_fit_[i] = fit;
      last_F_[i] = F;
    }
    if (fit > pbest_fit_[i]) {
      pbest_[i] = x;
      pbest_fit_[i] = fit;
      pbest_F_[i] = F;
    }
    if (fit > best.fit) best = Best{fit, x, F};
  }
}

void PeMatcher::mutate_pbests(int pop, Best& best, PeMatchResult& out) {
  const PeMatchParams& P = params_;
  const int N = static_cast<int>(num_matches_);
  const double dimension = static_cast<double>(N - 1);  // eq. 10 search range
  const int nd = std::min(std::max(1, P.num_differences), 16);
  const ParticlePos* a[16];
  const ParticlePos* b[16];
  Eigen::Matrix3d F;
  for (int i = 0; i < pop; ++i) {
    // n random pairs r2 != r3 (both != i when possible).
    for (int k = 0; k < nd; ++k) {
      int r2, r3;
      do {
        r2 = std::min(pop - 1, static_cast<int>(rng_.uniform() * pop));
      } while (r2 == i);
      do {
        r3 = std::min(pop - 1, static_cast<int>(rng_.uniform() * pop));
      } while (r3 == i || r3 == r2);
      a[k] = &pbest_[r2];
      b[k] = &pbest_[r3];
    }
    const double f = pe_mutation_perturbation(pe_difference_degree(a, b, nd, N), dimension);
    // h_i = Pbest_i + f(D) (eq. 10), then eq. 11 per component (binomial
    // crossover as in DE, whence the mutation comes): component from h_i
    // when rand <= L, else from Pbest_i.
    ParticlePos trial = pbest_[i];
    bool changed = false;
    for (int c = 0; c < kDim; ++c) {
      if (rng_.uniform() <= P.crossover_prob) {
        trial[c] += f;
        changed = true;
      }
    }
    if (!changed) continue;
    pe_repair_position(trial, nullptr, idx_, N);
    if (trial == pbest_[i]) continue;  // same indices after repair: nothing to try
    const int fit = evaluate(idx_, F);
    ++out.evaluations;
    if (!P.greedy_pbest || fit >= pbest_fit_[i]) {
      pbest_[i] = trial;
      pbest_fit_[i] = fit;
      pbest_F_[i] = F;
    }
    if (fit > best.fit) best = Best{fit, trial, F};
  }
}

void PeMatcher::filter_matches(const Eigen::Matrix3d& F_best, PeMatchResult& out) const {
  const int N = static_cast<int>(num_matches_);
  Eigen::Matrix3d Fbest = F_best / F_best.norm();
  auto count_inliers = [&](const Eigen::Matrix3d& Fm) {
    int cnt = 0;
    for (int i = 0; i < N; ++i) cnt += is_inlier(Fm, matches_[i]) ? 1 : 0;
    return cnt;
  };
  if (params_.refine) {
    // Beyond the paper: IRLS on the Sampson distance over all inliers; kept
    // only if it does not lose inliers under the chosen distance.
    Eigen::Matrix3d Fr = Fbest;
    if (refine_fundamental_irls(matches_, num_matches_, params_.inlier_threshold_px, params_.refine_iterations,
                                Fr) &&
        count_inliers(Fr) >= count_inliers(Fbest))
      Fbest = Fr;
  }
  // Step 8: filter all coarse matches with the output F.
  for (int i = 0; i < N; ++i) {
    const bool in = is_inlier(Fbest, matches_[i]);
    out.inlier_mask[i] = in ? 1 : 0;
    out.num_inliers += in ? 1 : 0;
  }
  out.F = Fbest;
}

void PeMatcher::match(const PointMatch* matches, std::size_t n, PeMatchResult& out) {
  out.F.reset();
  out.inlier_mask.assign(n, 0);
  out.num_inliers = 0;
  out.fitness = 0;
  out.iterations = 0;
  out.evaluations = 0;
  if (n < static_cast<std::size_t>(kDim)) return;
  const int pop = std::max(1, params_.population);
  prepare(matches, n);
  Best best = init_swarm(pop, out);
  int stall = 0;
  int iter = 0;
  while (iter < params_.max_iterations && stall < params_.stall_iterations) {
    ++iter;
    const int fit_before = best.fit;
    move_particles(pop, best, out);
    if (pop >= 3) mutate_pbests(pop, best, out);
    // Step 7: stop when Gbest has not improved for stall_iterations.
    stall = (best.fit > fit_before) ? 0 : stall + 1;
  }
  out.iterations = iter;
  out.fitness = std::max(best.fit, 0);
  if (best.fit < 0) return;  // every sample degenerate: no model
  filter_matches(best.F, out);
}

}  // namespace pvb::slam
