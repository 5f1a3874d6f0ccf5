// The factories of inertial_cost_functions.hpp: the one place the inertial
// cost functions' jets are compiled.
#include "inertial_cost_functions.hpp"

#include "inertial_costs.hpp"

namespace pvb::slam::optim_detail {

std::unique_ptr<ceres::CostFunction> make_imu_cost(const ImuPreintegration& pre, const geom::SE3d& T_b_c,
                                                   const Eigen::Vector3d& g_w) {
  return std::make_unique<ImuCost>(pre, T_b_c, g_w);
}

std::unique_ptr<ceres::CostFunction> make_imu_cost_free_gravity(const ImuPreintegration& pre,
                                                                const geom::SE3d& T_b_c) {
  return std::make_unique<ImuCostFreeGravity>(pre, T_b_c);
}

std::unique_ptr<ceres::CostFunction> make_bias_walk_cost(const ImuPreintegration& pre) {
  return std::make_unique<BiasWalkCost>(pre);
}

std::unique_ptr<ceres::CostFunction> make_wheel_planar_cost(const WheelPreintegration& pre,
                                                            const geom::SE3d& T_base_c) {
  return std::make_unique<WheelPlanarCost>(pre, T_base_c);
}

std::unique_ptr<ceres::CostFunction> make_wheel_tilt_cost(const WheelPreintegration& pre, const geom::SE3d& T_base_c) {
  return std::make_unique<WheelTiltCost>(pre, T_base_c);
}

std::unique_ptr<ceres::CostFunction> make_gravity_cost(const Eigen::Vector3d& f_c, const Eigen::Vector3d& g_w,
                                                       double sigma_rad) {
  return std::make_unique<GravityCost>(f_c, g_w, sigma_rad);
}

}  // namespace pvb::slam::optim_detail
