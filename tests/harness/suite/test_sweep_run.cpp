// A real two-seed sweep of the default scenario (a few frames each), then
// the Slurm array script for a third seed and --aggregate-only over all
// three.  Label `scenario`: it runs `pvbench run` three times.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"

namespace fs = std::filesystem;
using pvb::test::run_pvbench;

namespace {
constexpr int kFrames = 12;
}  // namespace

TEST(SweepRun, TwoSeedsThenASlurmTaskThenAggregateOnly) {
  const fs::path out = fs::path(::testing::TempDir()) / ("pvb_sweep_run_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string scenario = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  // Dense maps are written, not scored: what a sweep does with the runs is under test.
  const std::string common = " --frames " + std::to_string(kFrames) + " --compare --sync --no-map-eval";

  const auto r =
      run_pvbench("sweep --scenario " + scenario + " --seeds 1,2 --jobs 2 --out " + out.string() + common);
  ASSERT_EQ(r.code, 0) << r.output;
  for (int seed : {1, 2}) {
    const fs::path dir = out / ("seed_" + std::to_string(seed));
    ASSERT_TRUE(fs::exists(dir / "metrics.json")) << dir;
    const std::string metrics = pvb::read_file((dir / "metrics.json").string());
    EXPECT_NE(metrics.find("\"seed\": " + std::to_string(seed)), std::string::npos) << metrics.substr(0, 300);
    EXPECT_NE(pvb::read_file((dir / "stdout.log").string()).find("pvbench run: scenario pv_station"),
              std::string::npos);
    EXPECT_NE(r.output.find("seed " + std::to_string(seed) + ": exit 0; completed"), std::string::npos)
        << r.output;
  }
  const std::string md = pvb::read_file((out / "aggregate.md").string());
  EXPECT_NE(md.find("2 seeds, 2 with metrics, 0 failed"), std::string::npos) << md;
  EXPECT_NE(md.find("| baseline (ORB-SLAM2 motion model) | 2 |"), std::string::npos) << md;
  // --compare: the paired PE − baseline line is printed last and is the one in aggregate.md.
  const std::size_t last = r.output.rfind('\n', r.output.size() - 2);
  ASSERT_NE(last, std::string::npos) << r.output;
  const std::string paired = r.output.substr(last + 1);
  EXPECT_EQ(paired.rfind("PE-SLAM − baseline ATE: mean ", 0), 0u) << r.output;
  EXPECT_NE(paired.find(" mm over 2 seeds (effect size d_z "), std::string::npos) << paired;
  EXPECT_NE(md.find("\n" + paired), std::string::npos) << md;
  for (const char* f : {"aggregate.csv", "aggregate.json", "aggregate.svg", "aggregate.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  // The Slurm script runs the same self-contained command for its task's
  // seed.  Seed 2 again, into another folder: sync mode is bit-identical.
  const fs::path slurm_out = out / "slurm";
  const std::string slurm = "cd " + std::string(PVB_SOURCE_DIR) +
                            " && SLURM_ARRAY_TASK_ID=2 PVBENCH=" + pvb::test::pvbench_path() +
                            " bash scripts/slurm_sweep.sh " + scenario + " " + slurm_out.string() + common;
  ASSERT_EQ(std::system(slurm.c_str()), 0) << slurm;
  EXPECT_EQ(pvb::read_file((slurm_out / "seed_2" / "CameraTrajectory.txt").string()),
            pvb::read_file((out / "seed_2" / "CameraTrajectory.txt").string()));
  // A copy of seed 2 standing in for seed 3 is another seed's run: refused.
  fs::copy(slurm_out / "seed_2", out / "seed_3", fs::copy_options::recursive);
  const auto copied = run_pvbench("sweep --out " + out.string() + " --aggregate-only");
  EXPECT_EQ(copied.code, 1) << copied.output;
  EXPECT_NE(copied.output.find("seed_3/metrics.json: seed: expected 3 (the folder seed_3), got 2"), std::string::npos)
      << copied.output;
  // The third task for real, run again over the copy (its command carries --overwrite).
  const std::string task3 = "cd " + std::string(PVB_SOURCE_DIR) + " && SLURM_ARRAY_TASK_ID=3 PVBENCH=" +
                            pvb::test::pvbench_path() + " bash scripts/slurm_sweep.sh " + scenario + " " +
                            out.string() + common;
  ASSERT_EQ(std::system(task3.c_str()), 0) << task3;

  const auto agg = run_pvbench("sweep --out " + out.string() + " --aggregate-only");
  EXPECT_EQ(agg.code, 0) << agg.output;
  EXPECT_NE(pvb::read_file((out / "aggregate.md").string()).find("3 seeds, 3 with metrics, 0 failed"),
            std::string::npos);
  EXPECT_NE(agg.output.find(" mm over 3 seeds (effect size d_z "), std::string::npos) << agg.output;
  fs::remove_all(out);
}

// --sensors and --compare-sensors reach every seed's run: each metrics.json
// says the setup it fused, and the aggregate names the two setups.
TEST(SweepRun, SensorSetupsReachEverySeedsRun) {
  const fs::path out = fs::path(::testing::TempDir()) / ("pvb_sweep_sensors_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const std::string scenario = std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml";
  const std::string common = " --frames " + std::to_string(kFrames) + " --sync --no-map-eval --seeds 1";

  const auto pair = run_pvbench("sweep --scenario " + scenario + " --out " + (out / "pair").string() + common +
                                " --compare-sensors camera,camera+imu");
  ASSERT_EQ(pair.code, 0) << pair.output;
  const std::string m = pvb::read_file((out / "pair" / "seed_1" / "metrics.json").string());
  EXPECT_NE(m.find("\"sensors\": \"camera+imu\""), std::string::npos) << m.substr(0, 600);
  EXPECT_NE(m.find("    \"sensors\": \"camera\""), std::string::npos);  // the reference, under "baseline"
  EXPECT_NE(m.find("\"primary\": \"camera+imu\", \"reference\": \"camera\""), std::string::npos);
  EXPECT_NE(m.find("\"inertial\": {\"trusted\": "), std::string::npos);
  const std::string md = pvb::read_file((out / "pair" / "aggregate.md").string());
  EXPECT_NE(md.find("| camera+imu | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| camera | 1 |"), std::string::npos) << md;

  const auto one = run_pvbench("sweep --scenario " + scenario + " --out " + (out / "one").string() + common +
                               " --sensors camera+imu+wheels");
  ASSERT_EQ(one.code, 0) << one.output;
  const std::string m1 = pvb::read_file((out / "one" / "seed_1" / "metrics.json").string());
  EXPECT_NE(m1.find("\"sensors\": \"camera+imu+wheels\""), std::string::npos) << m1.substr(0, 600);
  EXPECT_NE(m1.find("\"dead_reckoned_frames\": "), std::string::npos);
  EXPECT_EQ(m1.find("\"baseline\""), std::string::npos);
  EXPECT_NE(pvb::read_file((out / "one" / "seed_1" / "run.log").string()).find("sensors camera+imu+wheels"),
            std::string::npos);
  fs::remove_all(out);
}
