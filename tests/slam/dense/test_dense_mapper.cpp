// The DenseMapper: several views of a plane at known poses give a cloud on
// the plane; the worker thread gives the same cloud as synchronous mode;
// re-posing a keyframe moves its points; pose updates carry the corrected
// map to the map built from scratch, and leave the live map alone.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "pvb/slam/dense/dense_mapper.hpp"
#include "pvb/slam/dense/ply.hpp"
#include "synthetic.hpp"

namespace {

using pvb::geom::make_se3;
using pvb::geom::SE3d;
using pvb::geom::so3_exp;
using pvb::slam::dense::CloudPoint;
using pvb::slam::dense::DenseKeyFrame;
using pvb::slam::dense::DenseMapper;
using pvb::slam::dense::DenseMapperOptions;
using pvb::slam::dense::PointCloud;
using pvb::slam::dense::PoseUpdate;

// The plane z_w = 2.5 m, seen by cameras looking roughly along +z_w.
const Eigen::Vector3d kNormal(0, 0, 1);
constexpr double kPlaneD = 2.5;

std::vector<SE3d> view_poses() {
  std::vector<SE3d> T_w_c;
  for (int i = 0; i < 6; ++i) {
    const double a = 0.05 * i;
    T_w_c.push_back(make_se3(so3_exp(Eigen::Vector3d(0.08 * std::sin(3 * a), -0.1 + a * 0.4, 0.2 * a)),
                             Eigen::Vector3d(0.3 * i, -0.1 * i, 0.05 * i)));
  }
  return T_w_c;
}

DenseMapperOptions options() {
  DenseMapperOptions o;
  o.K = pvb::test::small_camera();
  o.back_projection.stride_px = 2;
  o.back_projection.min_depth_m = 0.1;
  o.back_projection.max_depth_m = 6.0;
  o.leaf_m = 0.02;
  return o;
}

DenseKeyFrame keyframe(std::uint64_t id, const SE3d& T_w_c) {
  const pvb::test::PlaneView v = pvb::test::render_plane(pvb::test::small_camera(), T_w_c, kNormal, kPlaneD);
  return {id, static_cast<std::int64_t>(id) * 100000000, v.rgb, v.depth_m, T_w_c};
}

TEST(DenseMapper, ViewsOfAPlaneGiveACloudOnThePlane) {
  DenseMapper mapper(options());
  const std::vector<SE3d> poses = view_poses();
  for (std::size_t i = 0; i < poses.size(); ++i) mapper.insert(keyframe(i, poses[i]));
  EXPECT_EQ(mapper.stats().keyframes, poses.size());
  const PointCloud cloud = mapper.global_cloud();
  ASSERT_GT(cloud.size(), 1000u);
  double worst = 0;
  for (const CloudPoint& p : cloud)
    worst = std::max(worst, std::abs(kNormal.dot(Eigen::Vector3d(p.x, p.y, p.z)) - kPlaneD));
  EXPECT_LT(worst, 1e-4);  // voxel means of coplanar points stay on the plane (float rounding only)
  // the global voxel filter merged the overlapping views: fewer points than all keyframe clouds together
  EXPECT_LT(cloud.size(), mapper.stats().points);
  // and every point is seen by at least one view
  for (const CloudPoint& p : cloud) {
    bool seen = false;
    for (const SE3d& T_w_c : poses) {
      const auto uv = options().K.project(T_w_c.inverse() * Eigen::Vector3d(p.x, p.y, p.z));
      seen = seen || (uv && options().K.in_image(*uv, -3.0));  // a voxel mean may sit a pixel or two outside
    }
    ASSERT_TRUE(seen) << p.x << " " << p.y << " " << p.z;
  }
}

TEST(DenseMapper, WrongPosesGiveACloudOffThePlane) {
  // The same views inserted with the inverse poses (a T_c_w / T_w_c mix-up)
  // do not form a plane: the plane test above can fail.
  DenseMapper mapper(options());
  const std::vector<SE3d> poses = view_poses();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    DenseKeyFrame kf = keyframe(i, poses[i]);
    kf.T_w_c = poses[i].inverse();
    mapper.insert(std::move(kf));
  }
  double worst = 0;
  for (const CloudPoint& p : mapper.global_cloud())
    worst = std::max(worst, std::abs(kNormal.dot(Eigen::Vector3d(p.x, p.y, p.z)) - kPlaneD));
  EXPECT_GT(worst, 0.05);
}

TEST(DenseMapper, WorkerGivesTheSameCloudAsSynchronousMode) {
  const std::vector<SE3d> poses = view_poses();
  DenseMapper sync(options());
  DenseMapper worker(options());
  worker.start();
  EXPECT_TRUE(worker.running());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    sync.insert(keyframe(i, poses[i]));
    worker.insert(keyframe(i, poses[i]));
  }
  worker.stop();
  EXPECT_FALSE(worker.running());
  EXPECT_EQ(worker.stats().keyframes, poses.size());
  const PointCloud a = sync.global_cloud(), b = worker.global_cloud();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0u);
  EXPECT_TRUE(a == b);  // bit-identical
  // after stop() keyframes are processed inline
  worker.insert(keyframe(99, poses[0]));
  EXPECT_EQ(worker.stats().keyframes, poses.size() + 1);
}

TEST(DenseMapper, StopWithoutStartAndDestructorWithQueuedWork) {
  DenseMapper idle(options());
  idle.stop();  // nothing to join
  {
    DenseMapper m(options());
    m.start();
    for (const SE3d& T : view_poses()) m.insert(keyframe(0, T));
  }  // the destructor drains the queue and joins
  SUCCEED();
}

TEST(DenseMapper, RePosingAKeyframeMovesItsPoints) {
  DenseMapper mapper(options());
  const std::vector<SE3d> poses = view_poses();
  mapper.insert(keyframe(0, poses[0]));
  mapper.insert(keyframe(1, poses[1]));
  const PointCloud kf1_c = mapper.keyframe_cloud(1);
  ASSERT_FALSE(kf1_c.empty());
  // a bundle adjustment moved keyframe 1 by 0.5 m along x_w and turned it a little
  const SE3d corrected =
      make_se3(so3_exp(Eigen::Vector3d(0, 0, 0.05)), Eigen::Vector3d(0.5, 0, 0)) * poses[1];
  const PointCloud moved = mapper.global_cloud({{1, corrected}});
  // expected: keyframe 0 as inserted, keyframe 1 at its new pose
  PointCloud expect = pvb::slam::dense::transform(mapper.keyframe_cloud(0), poses[0]);
  pvb::slam::dense::append(expect, pvb::slam::dense::transform(kf1_c, corrected));
  expect = pvb::slam::dense::voxel_filter(expect, options().leaf_m);
  ASSERT_EQ(moved.size(), expect.size());
  EXPECT_TRUE(moved == expect);  // bit-identical
  // and the old cloud differs: keyframe 1's points left their old place
  const PointCloud old = mapper.global_cloud();
  Eigen::Vector3d c_old = Eigen::Vector3d::Zero(), c_new = Eigen::Vector3d::Zero();
  for (const CloudPoint& p : old) c_old += Eigen::Vector3d(p.x, p.y, p.z) / static_cast<double>(old.size());
  for (const CloudPoint& p : moved)
    c_new += Eigen::Vector3d(p.x, p.y, p.z) / static_cast<double>(moved.size());
  EXPECT_GT((c_new - c_old).x(), 0.1);
  // the moved keyframe's points, taken back through the corrected pose, are its camera-frame cloud
  const PointCloud only1 = [&] {
    DenseMapper single(options());
    single.insert(keyframe(1, poses[1]));
    return single.global_cloud({{1, corrected}});
  }();
  const PointCloud back = pvb::slam::dense::transform(only1, corrected.inverse());
  for (const CloudPoint& p : back) {
    const auto uv = options().K.project(Eigen::Vector3d(p.x, p.y, p.z));
    ASSERT_TRUE(uv);
    EXPECT_TRUE(options().K.in_image(*uv, -3.0));
  }
}

double worst_off_plane(const PointCloud& cloud) {
  double worst = 0;
  for (const CloudPoint& p : cloud)
    worst = std::max(worst, std::abs(kNormal.dot(Eigen::Vector3d(p.x, p.y, p.z)) - kPlaneD));
  return worst;
}

// Keyframes inserted at poses off by a few centimetres (drift), then the
// true poses posted as a loop correction would.
std::unique_ptr<DenseMapper> drifted_mapper(bool worker, std::size_t budget_bytes = 0) {
  DenseMapperOptions o = options();
  o.memory_budget_bytes = budget_bytes;
  auto owner = std::make_unique<DenseMapper>(o);
  DenseMapper& mapper = *owner;
  if (worker) mapper.start();
  const std::vector<SE3d> poses = view_poses();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    DenseKeyFrame kf = keyframe(i, poses[i]);
    kf.T_w_c = make_se3(so3_exp(Eigen::Vector3d(0.01 * i, 0, 0)), Eigen::Vector3d(0, 0, 0.02 * i)) * poses[i];
    mapper.insert(std::move(kf));
  }
  PoseUpdate update;
  for (std::size_t i = 0; i < poses.size(); ++i) update.T_w_c_by_id[i] = poses[i];
  update.loop_correction = true;
  mapper.update_poses(update);
  mapper.stop();
  return owner;
}

TEST(DenseMapper, PoseUpdatesBringTheCorrectedMapToTheMapFromScratch) {
  const auto owner = drifted_mapper(false);
  const DenseMapper& mapper = *owner;
  std::map<std::uint64_t, SE3d> truth;
  const std::vector<SE3d> poses = view_poses();
  for (std::size_t i = 0; i < poses.size(); ++i) truth[i] = poses[i];
  const PointCloud corrected = mapper.corrected_cloud(), scratch = mapper.global_cloud(truth);
  ASSERT_EQ(corrected.size(), scratch.size());
  for (std::size_t i = 0; i < corrected.size(); ++i) ASSERT_NEAR(corrected[i].z, scratch[i].z, 2e-6);
  EXPECT_LT(worst_off_plane(corrected), 1e-4);
  EXPECT_GT(worst_off_plane(mapper.live_cloud()), 0.05);  // the live map keeps the drift
  // keyframe 0 had no drift: 5 of 6 moved
  EXPECT_EQ(mapper.stats().keyframes_moved, poses.size() - 1);
  ASSERT_EQ(mapper.stats().loop_update_ms.size(), 1u);
  const auto loop = mapper.first_loop();
  ASSERT_TRUE(loop);
  EXPECT_EQ(loop->keyframes_moved, poses.size() - 1);
  EXPECT_GT(worst_off_plane(loop->before), 0.05);
  EXPECT_TRUE(loop->after == corrected);
}

TEST(DenseMapper, WorkerAppliesTheSameUpdatesAsSynchronousMode) {
  const auto sync = drifted_mapper(false), worker = drifted_mapper(true);
  EXPECT_TRUE(sync->corrected_cloud() == worker->corrected_cloud());
  EXPECT_TRUE(sync->live_cloud() == worker->live_cloud());
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(DenseMapper, ABudgetSpillsAndGivesTheSameMapsAndFiles) {
  const auto unbounded = drifted_mapper(false), bounded = drifted_mapper(true, 16 * 1024);
  const pvb::slam::dense::DenseMemory m = bounded->memory();
  EXPECT_GT(m.keyframes_spilled, 0u);
  EXPECT_GT(m.spilled_keyframe_bytes, 0u);
  EXPECT_GT(m.spilled_map_bytes, 0u);
  EXPECT_GT(unbounded->memory().total(), 4 * m.total());
  EXPECT_TRUE(bounded->corrected_cloud() == unbounded->corrected_cloud());
  EXPECT_TRUE(bounded->live_cloud() == unbounded->live_cloud());
  EXPECT_TRUE(bounded->global_cloud() == unbounded->global_cloud());
  EXPECT_TRUE(bounded->keyframe_cloud(0) == unbounded->keyframe_cloud(0));
  const auto loop_b = bounded->first_loop(), loop_u = unbounded->first_loop();
  ASSERT_TRUE(loop_b && loop_u);
  EXPECT_TRUE(loop_b->before == loop_u->before);
  EXPECT_TRUE(loop_b->after == loop_u->after);
  // The streamed files hold what write_ply() writes of the whole clouds.
  const std::string dir = ::testing::TempDir();
  EXPECT_EQ(bounded->write_corrected_ply(dir + "/c.ply"), unbounded->corrected_cloud().size());
  pvb::slam::dense::write_ply(dir + "/c_whole.ply", unbounded->corrected_cloud());
  EXPECT_EQ(file_bytes(dir + "/c.ply"), file_bytes(dir + "/c_whole.ply"));
  bounded->write_live_ply(dir + "/l.ply");
  pvb::slam::dense::write_ply(dir + "/l_whole.ply", unbounded->live_cloud());
  EXPECT_EQ(file_bytes(dir + "/l.ply"), file_bytes(dir + "/l_whole.ply"));
  ASSERT_TRUE(bounded->write_first_loop_ply(dir + "/b.ply", dir + "/a.ply"));
  pvb::slam::dense::write_ply(dir + "/b_whole.ply", loop_u->before);
  EXPECT_EQ(file_bytes(dir + "/b.ply"), file_bytes(dir + "/b_whole.ply"));
  EXPECT_FALSE(DenseMapper(options()).write_first_loop_ply(dir + "/x.ply", dir + "/y.ply"));
}

TEST(DenseMapper, SmallMovesWaitUnlessExact) {
  DenseMapper mapper(options());
  const SE3d T = view_poses()[2];
  mapper.insert(keyframe(0, T));
  const PointCloud before = mapper.corrected_cloud();
  const SE3d nudged = make_se3(SE3d::Identity().linear(), Eigen::Vector3d(0.0004, 0, 0)) * T;  // 0.4 mm
  mapper.update_poses({{{0, nudged}}, false, false});
  EXPECT_TRUE(mapper.corrected_cloud() == before);
  EXPECT_EQ(mapper.stats().keyframes_moved, 0u);
  mapper.update_poses({{{0, nudged}}, false, true});
  EXPECT_FALSE(mapper.corrected_cloud() == before);
  EXPECT_EQ(mapper.stats().keyframes_moved, 1u);
  mapper.update_poses({{{0, T}, {7, T}}, false, true});  // back again; an unknown id is ignored
  EXPECT_TRUE(mapper.corrected_cloud() == before);        // exactly: the sums are integers
  EXPECT_FALSE(mapper.first_loop());
}

}  // namespace
