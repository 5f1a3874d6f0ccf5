// Every pvbench command with each of its outputs pointed at each of its
// inputs (the same file, through a link, or an output folder that holds the
// input and would be emptied): one error line naming the output, a
// non-zero exit before any work, and the input byte for byte as it was.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"
#include "shared_data.hpp"

using namespace pvb;
namespace fs = std::filesystem;

namespace {

/// A folder of inputs of every kind the commands read, made once.
class Inputs {
 public:
  Inputs() : dir_(::testing::TempDir() + "pvb_out_on_in_" + std::to_string(::getpid())) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::copy_file(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml", file("station.yaml"));
    write_file(file("day.yaml"), "base: station.yaml\nname: day\nseed: 3\n");
    write_file(file("campaign.yaml"),
               "name: c\nsessions:\n  - {name: a, scenario: " + file("day.yaml") + ", mode: map}\n");
    fs::copy(test::shared_path("data/tum/fr1_xyz_pair"), file("seq"), fs::copy_options::recursive);
    fs::copy_file(test::shared_path("data/tum/TUM1.yaml"), file("TUM1.yaml"));
    for (const char* img : {"img1.ppm", "img2.ppm", "H1to2p"})
      fs::copy_file(test::shared_path(std::string("data/oxford/wall/") + img), file(img));
    const std::string traj = "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n3.0 2 0 0 0 0 0 1\n";
    write_file(file("gt.txt"), traj);
    write_file(file("est.txt"), traj);
    write_file(file("map.pvbmap"), "not read: the refusal comes first");
    write_file(file("cloud.ply"), "not read either");
    fs::create_symlink("station.yaml", file("link.yaml"));
  }
  std::string file(const std::string& name) const { return dir_ + "/" + name; }
  /// An earlier pvbench output folder (it holds the marker) with a copy of
  /// input `name` in it: {the folder, the copy}.
  std::pair<std::string, std::string> output_folder_holding(const std::string& name) const {
    const std::string out = file("out_" + std::to_string(counter_++));
    fs::create_directories(out);
    write_file(out + "/.pvbench", "written by pvbench run\n");
    fs::copy(file(name), out + "/" + name, fs::copy_options::recursive);
    return {out, out + "/" + name};
  }

 private:
  std::string dir_;
  mutable int counter_ = 0;
};

const Inputs& inputs() {
  static const Inputs in;
  return in;
}

struct Case {
  std::string args;   ///< after "pvbench"
  std::string input;  ///< the file that must stay as it was
  std::string says;   ///< in the one error line
};

/// Runs the case: exit 1, one error line saying `says`, `input` unchanged.
void expect_refused(const Case& c) {
  const std::string before = read_file(c.input);
  const test::RunResult r = test::run_pvbench_from_source("", c.args);
  EXPECT_EQ(r.code, 1) << c.args << "\n" << r.output;
  EXPECT_EQ(r.output.find("pvbench: error: "), r.output.rfind("pvbench: error: ")) << r.output;
  EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
  EXPECT_EQ(read_file(c.input), before) << c.input << " changed by " << c.args;
}

constexpr const char* kIsInput = ", an input of this command; give ";
constexpr const char* kHolds = "an input of this command, which --overwrite would remove";

}  // namespace

TEST(OutputsOnInputs, RecordRunSlamCampaignAndSweepRefuseAnOutputOnAnInput) {
  const Inputs& in = inputs();
  const std::string st = in.file("station.yaml"), day = in.file("day.yaml"), seq = in.file("seq");
  const std::string tum1 = in.file("TUM1.yaml"), map = in.file("map.pvbmap");
  const std::string slam = "slam --sequence " + seq + " --settings " + tum1 + " --sync ";
  const auto [rec_out, rec_st] = in.output_folder_holding("station.yaml");
  const auto [run_out, run_map] = in.output_folder_holding("map.pvbmap");
  const auto [slam_out, slam_tum1] = in.output_folder_holding("TUM1.yaml");
  const auto [cam_out, cam_campaign] = in.output_folder_holding("campaign.yaml");
  const auto [sweep_out, sweep_st] = in.output_folder_holding("station.yaml");
  // A scenario where --aggregate-only writes its table (a YAML file named so).
  const std::string agg_dir = in.file("agg"), agg_scenario = agg_dir + "/aggregate.md";
  fs::create_directories(agg_dir);
  fs::copy_file(st, agg_scenario, fs::copy_options::overwrite_existing);
  const std::vector<Case> cases = {
      {"record --scenario " + rec_st + " --overwrite --out " + rec_out, rec_st, kHolds},
      {"run --scenario " + st + " --out " + in.file("r1") + " --save-map " + st, st, kIsInput},
      {"run --scenario " + st + " --out " + in.file("r2") + " --save-map " + in.file("link.yaml"), st,
       kIsInput},
      {"run --scenario " + day + " --out " + in.file("r3") + " --save-map " + st, st,
       "a base of the --scenario"},
      {"run --scenario " + st + " --out " + in.file("r4") + " --map " + map +
           " --map-mode extend --save-map " + map,
       map, "is the --map file"},
      {"run --scenario " + st + " --overwrite --out " + run_out + " --map " + run_map +
           " --map-mode localise",
       run_map, kHolds},
      {slam + "--out " + in.file("s1") + " --save-map " + seq + "/rgb.txt", seq + "/rgb.txt",
       "of the --sequence"},
      {slam + "--out " + in.file("s2") + " --save-map " + seq + "/associations.txt", seq + "/rgb.txt",
       "of the --sequence"},
      {slam + "--out " + in.file("s3") + " --save-map " + tum1, tum1, "is the --settings file"},
      {slam + "--out " + in.file("s4") + " --map " + map + " --map-mode extend --save-map " + map, map,
       kIsInput},
      {"slam --sequence " + seq + " --settings " + slam_tum1 + " --overwrite --out " + slam_out, slam_tum1,
       kHolds},
      {"campaign --campaign " + cam_campaign + " --overwrite --out " + cam_out, cam_campaign, kHolds},
      {"sweep --scenario " + sweep_st + " --seeds 1 --overwrite --out " + sweep_out, sweep_st, kHolds},
      {"sweep --scenario " + agg_scenario + " --aggregate-only --out " + agg_dir + " --seeds 1", agg_scenario,
       "is the --scenario file"},
  };
  for (const Case& c : cases) expect_refused(c);
}

TEST(OutputsOnInputs, CameraRefusesAnOutputOnAnInput) {
  if (test::run_pvbench("camera --help").code != 0)
    GTEST_SKIP() << "pvbench has no camera command (no OpenNI2)";
  const Inputs& in = inputs();
  const std::string st = in.file("station.yaml"), map = in.file("map.pvbmap");
  const std::string cam = "camera --uri sim://" + st + " --sync --out " + in.file("c1");
  const std::vector<Case> cases = {
      {cam + " --save-map " + st, st, "is the sim:// scenario file"},
      {cam + " --settings " + in.file("TUM1.yaml") + " --save-map " + in.file("TUM1.yaml"),
       in.file("TUM1.yaml"), "is the --settings file"},
      {cam + " --map " + map + " --map-mode extend --save-map " + map, map, "is the --map file"},
      {cam + " --record " + in.file("x.oni") + " --save-map " + in.file("x.oni"), st, "name the same file"},
  };
  for (const Case& c : cases) expect_refused(c);
}

TEST(OutputsOnInputs, EvalMatchVocabSheetAndEvalMapRefuseAnOutputOnAnInput) {
  const Inputs& in = inputs();
  const std::string gt = in.file("gt.txt"), est = in.file("est.txt"), st = in.file("station.yaml");
  const std::string eval = "eval --gt " + gt + " --est " + est;
  const std::string img1 = in.file("img1.ppm"), img2 = in.file("img2.ppm"), h = in.file("H1to2p");
  const std::string match = "match --img1 " + img1 + " --img2 " + img2 + " --homography " + h + " --runs 1";
  const auto [em_out, cloud] = in.output_folder_holding("cloud.ply");
  const std::vector<Case> cases = {
      {eval + " --json " + gt, gt, "is the --gt trajectory"},
      {eval + " --json " + est, est, "is an --est trajectory"},
      {eval + " --plot " + est, est, kIsInput},
      {eval + " --json " + in.file("x.json") + " --plot " + in.file("x.json"), gt, "name the same file"},
      {match + " --json " + img1, img1, "is the --img1 image"},
      {match + " --draw " + img2, img2, "is the --img2 image"},
      {match + " --json " + h, h, "is the --homography file"},
      {"vocab --scenario " + st + " --out " + st, st, kIsInput},
      {"vocab --sequence " + in.file("seq") + " --out " + in.file("seq") + "/depth.txt",
       in.file("seq/depth.txt"), "of the --sequence folder"},
      {"sheet --scenario " + st + " --out " + st, st, kIsInput},
      {"eval-map --map " + cloud + " --scenario " + st + " --trajectory " + est + " --gt " + gt +
           " --overwrite --out " + em_out,
       cloud, kHolds},
  };
  for (const Case& c : cases) expect_refused(c);
}

TEST(OutputsOnInputs, AnEmptyOutputPathIsAnErrorNotNoOutput) {
  const Inputs& in = inputs();
  const test::RunResult r = test::run_pvbench_from_source(
      "", "run --scenario " + in.file("station.yaml") + " --out " + in.file("e1") + " --save-map ''");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("pvbench run: --save-map: expected a path, got an empty one"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(in.file("e1")));
}

TEST(OutputsOnInputs, AMapIntoAMissingFolderOrOntoAFolderIsRefusedBeforeTheRun) {
  const Inputs& in = inputs();
  for (const auto& [save, says] : std::vector<std::pair<std::string, std::string>>{
           {in.file("missing/m.pvbmap"), "the folder " + in.file("missing") + " does not exist"},
           {in.file("seq"), "the --save-map output is a folder"}}) {
    const test::RunResult r = test::run_pvbench_from_source(
        "", "run --scenario " + in.file("station.yaml") + " --out " + in.file("f1") + " --save-map " + save);
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(in.file("f1"))) << "the run began";
  }
}

TEST(OutputsOnInputs, ABadMapLeavesNoOutputFolder) {
  // The map is read (and refused) before the folder is made, so the same
  // command with a good map needs no --overwrite.
  const Inputs& in = inputs();
  const std::string out = in.file("badmap");
  const test::RunResult r =
      test::run_pvbench_from_source("", "run --scenario " + in.file("station.yaml") + " --out " + out +
                                            " --map " + in.file("map.pvbmap") + " --map-mode localise");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find(in.file("map.pvbmap") + ": "), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out)) << "the run made its folder before it read the map";
}
