#include "pvb/scenes/ground_relief.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace pvb::scenes {
namespace {

/// Uniform numbers in [0, 1) and standard normal ones from a seed, the
/// same on every platform (std::normal_distribution is not specified).
class ReliefRandom {
 public:
  explicit ReliefRandom(std::uint64_t seed) : gen_(seed * 0x9E3779B97F4A7C15ull + 0x6A09E667F3BCC909ull) {}
  double uniform() { return static_cast<double>(gen_() >> 11) / 9007199254740992.0; }
  double normal() {  // Box-Muller; 1 - u keeps the logarithm finite
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
  }

 private:
  std::mt19937_64 gen_;
};

/// One cosine of the roughness: wave vector (kx, ky) in rad/m and phase.
struct Wave {
  double kx = 0, ky = 0, phase = 0;
};

std::vector<Wave> draw_waves(double scale_m, std::uint64_t station_seed) {
  ReliefRandom rng(station_seed ^ 0x6E0DE11EFull);
  std::vector<Wave> waves(kReliefWaves);
  for (Wave& w : waves) {
    w.kx = rng.normal() / scale_m;
    w.ky = rng.normal() / scale_m;
    w.phase = 2.0 * M_PI * rng.uniform();
  }
  return waves;
}

/// Adds sigma sqrt(2 / K) sum_k cos(kx x + ky y + phase) at every sample:
/// cos(a + b) = cos a cos b - sin a sin b with a along the columns and b
/// along the rows, so that the cosines are taken once per column and row.
void add_roughness(const std::vector<Wave>& waves, double sigma_m, HeightGrid* g) {
  const double dx = 2.0 * g->half_x_m / (g->ncol - 1), dy = 2.0 * g->half_y_m / (g->nrow - 1);
  const double amp = sigma_m * std::sqrt(2.0 / static_cast<double>(waves.size()));
  std::vector<double> ca(static_cast<std::size_t>(g->ncol)), sa(ca.size());
  std::vector<double> cb(static_cast<std::size_t>(g->nrow)), sb(cb.size());
  for (const Wave& w : waves) {
    for (int c = 0; c < g->ncol; ++c) {
      const double a = w.kx * (-g->half_x_m + c * dx) + w.phase;
      ca[static_cast<std::size_t>(c)] = amp * std::cos(a);
      sa[static_cast<std::size_t>(c)] = amp * std::sin(a);
    }
    for (int r = 0; r < g->nrow; ++r) {
      const double b = w.ky * (-g->half_y_m + r * dy);
      cb[static_cast<std::size_t>(r)] = std::cos(b);
      sb[static_cast<std::size_t>(r)] = std::sin(b);
    }
    for (int r = 0; r < g->nrow; ++r) {
      double* row = g->z_m.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(g->ncol);
      const double cr = cb[static_cast<std::size_t>(r)], sr = sb[static_cast<std::size_t>(r)];
      for (int c = 0; c < g->ncol; ++c)
        row[c] += ca[static_cast<std::size_t>(c)] * cr - sa[static_cast<std::size_t>(c)] * sr;
    }
  }
}

}  // namespace

double HeightGrid::min_m() const { return z_m.empty() ? 0.0 : *std::min_element(z_m.begin(), z_m.end()); }
double HeightGrid::max_m() const { return z_m.empty() ? 0.0 : *std::max_element(z_m.begin(), z_m.end()); }

Eigen::Vector2i relief_samples(const Eigen::Vector2d& size_m, double cell_m) {
  const auto count = [cell_m](double extent) {
    return std::max(2, static_cast<int>(std::ceil(extent / cell_m - 1e-9)) + 1);
  };
  return {count(size_m.x()), count(size_m.y())};
}

GroundRelief::GroundRelief(const Scenario& s) {
  if (s.ground.relief)
    *this = GroundRelief(*s.ground.relief, s.ground.size_m, s.station_seed_or_seed(),
                         s.ground.tiling == GroundTiling::kVaried);
}

GroundRelief::GroundRelief(const Relief& r, const Eigen::Vector2d& size_m, std::uint64_t station_seed,
                           bool tiled)
    : relief_(true), tiled_(tiled) {
  const double az = r.slope_azimuth_deg * M_PI / 180.0, grade = r.slope_percent / 100.0;
  if (tiled) {  // the field itself, sampled when asked for
    if (r.amplitude_cm > 0)
      for (const Wave& w : draw_waves(r.scale_m, station_seed)) waves_.emplace_back(w.kx, w.ky, w.phase);
    amp_m_ = r.amplitude_cm / 100.0 * std::sqrt(2.0 / kReliefWaves);
    grade_x_ = grade * std::cos(az);
    grade_y_ = grade * std::sin(az);
    half_x_m_ = size_m.x() / 2;
    half_y_m_ = size_m.y() / 2;
    cells_per_tile_ = static_cast<int>(std::ceil(kReliefTileM / r.cell_m - 1e-9));
    lattice_m_ = kReliefTileM / cells_per_tile_;
    return;
  }
  const Eigen::Vector2i n = relief_samples(size_m, r.cell_m);
  grid_.ncol = n.x();
  grid_.nrow = n.y();
  grid_.half_x_m = size_m.x() / 2;
  grid_.half_y_m = size_m.y() / 2;
  grid_.z_m.assign(static_cast<std::size_t>(grid_.nrow) * static_cast<std::size_t>(grid_.ncol), 0.0);
  if (r.amplitude_cm > 0) add_roughness(draw_waves(r.scale_m, station_seed), r.amplitude_cm / 100.0, &grid_);
  const double dx = size_m.x() / (grid_.ncol - 1), dy = size_m.y() / (grid_.nrow - 1);
  for (int row = 0; row < grid_.nrow; ++row)
    for (int c = 0; c < grid_.ncol; ++c) {
      const double x = -grid_.half_x_m + c * dx, y = -grid_.half_y_m + row * dy;
      grid_.z_m[static_cast<std::size_t>(row) * static_cast<std::size_t>(grid_.ncol) +
                static_cast<std::size_t>(c)] += grade * (x * std::cos(az) + y * std::sin(az));
    }
}

double GroundRelief::sample_m(long long i, long long j) const {
  const double x = -half_x_m_ + static_cast<double>(i) * lattice_m_;
  const double y = -half_y_m_ + static_cast<double>(j) * lattice_m_;
  double z = grade_x_ * x + grade_y_ * y;
  for (const Eigen::Vector3d& w : waves_) z += amp_m_ * std::cos(w.x() * x + w.y() * y + w.z());
  return z;
}

GroundPoint GroundRelief::at(double x, double y) const {
  if (!relief_) return {};
  if (!tiled_) return grid_.at(x, y);
  // The lattice cell under (x, y) as a 2 x 2 grid, interpolated as MuJoCo does.
  const auto i = static_cast<long long>(std::floor((x + half_x_m_) / lattice_m_));
  const auto j = static_cast<long long>(std::floor((y + half_y_m_) / lattice_m_));
  const double z[4] = {sample_m(i, j), sample_m(i + 1, j), sample_m(i, j + 1), sample_m(i + 1, j + 1)};
  const double cx = -half_x_m_ + (static_cast<double>(i) + 0.5) * lattice_m_;
  const double cy = -half_y_m_ + (static_cast<double>(j) + 0.5) * lattice_m_;
  const double h = lattice_m_ / 2;
  return grid_surface(z, 1.0, 2, 2, h, h, x - cx, y - cy);
}

std::optional<RouteGradeFault> find_route_grade_fault(const GroundRelief& g,
                                                      const std::vector<Eigen::Vector2d>& route,
                                                      double wheel_base_m, double track_m) {
  for (std::size_t i = 0; i < route.size(); ++i) {
    const Eigen::Vector2d& p = route[i];
    const Eigen::Vector2d d = route[std::min(i + 1, route.size() - 1)] - route[i > 0 ? i - 1 : 0];
    if (d.norm() < 1e-9) continue;
    const Eigen::Vector2d t = d.normalized(), left(-t.y(), t.x());
    const double pitch = (g.height_m(p) - g.height_m(p - wheel_base_m * t)) / wheel_base_m;
    const double roll =
        (g.height_m(p + 0.5 * track_m * left) - g.height_m(p - 0.5 * track_m * left)) / track_m;
    if (std::abs(pitch) > kMaxRouteGrade) return RouteGradeFault{p, pitch, false};
    if (std::abs(roll) > kMaxRouteGrade) return RouteGradeFault{p, roll, true};
  }
  return std::nullopt;
}

}  // namespace pvb::scenes
