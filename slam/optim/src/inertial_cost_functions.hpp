#pragma once
// The inertial and wheel cost functions (inertial_costs.hpp), made in one
// source of pvb_slam_optim: a caller gets a ceres::CostFunction without
// compiling their jets again (the forward-mode derivatives of a 9-row IMU
// factor over 24 tangent columns are most of a compile).  Private to
// pvb_slam_optim (and its tests).
#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <memory>

#include "pvb/geometry/se3.hpp"
#include "pvb/slam/inertial/imu_preintegration.hpp"
#include "pvb/slam/inertial/wheel_preintegration.hpp"

namespace pvb::slam::optim_detail {

/// IMU factor (9 rows).  Blocks: pose i, v_i, bias i, pose j, v_j.
std::unique_ptr<ceres::CostFunction> make_imu_cost(const ImuPreintegration& pre, const geom::SE3d& T_b_c,
                                                   const Eigen::Vector3d& g_w);
/// IMU factor with gravity estimated (9 rows).  Blocks: those of
/// make_imu_cost, then g_w (3).
std::unique_ptr<ceres::CostFunction> make_imu_cost_free_gravity(const ImuPreintegration& pre,
                                                                const geom::SE3d& T_b_c);
/// Bias random walk (6 rows).  Blocks: bias i, bias j.
std::unique_ptr<ceres::CostFunction> make_bias_walk_cost(const ImuPreintegration& pre);
/// Wheel factor's planar increment (3 rows).  Blocks: pose i, pose j.
std::unique_ptr<ceres::CostFunction> make_wheel_planar_cost(const WheelPreintegration& pre,
                                                            const geom::SE3d& T_base_c);
/// Wheel factor's soft planar constraint (3 rows).  Blocks: pose i, pose j.
std::unique_ptr<ceres::CostFunction> make_wheel_tilt_cost(const WheelPreintegration& pre, const geom::SE3d& T_base_c);
/// Gravity direction of a camera (2 rows).  Block: the pose.
std::unique_ptr<ceres::CostFunction> make_gravity_cost(const Eigen::Vector3d& f_c, const Eigen::Vector3d& g_w,
                                                       double sigma_rad);

}  // namespace pvb::slam::optim_detail
