// Every pvbench command with each of its outputs pointed at each of its
// inputs: a file output given the input's path, a folder output given an
// earlier pvbench folder that holds the input (--overwrite would empty it).
// Each is one error line naming the input, exit 1 before any work, and the
// input byte for byte as it was.  (check and map-check write nothing.)
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "run_pvbench.hpp"
#include "shared_data.hpp"

using namespace pvb;
namespace fs = std::filesystem;

namespace {

/// The inputs every command below reads, by name: a file, or a folder
/// whose named file is the one a command reads ("seq" -> "seq/rgb.txt").
struct InputFiles {
  std::string dir;
  std::map<std::string, std::string> path;  ///< name -> what the command line names
  std::map<std::string, std::string> read;  ///< name -> the file that must stay unchanged
};

const InputFiles& inputs() {
  static const InputFiles in = [] {
    InputFiles f;
    f.dir = ::testing::TempDir() + "pvb_out_on_in_" + std::to_string(::getpid());
    fs::remove_all(f.dir);
    fs::create_directories(f.dir + "/images");
    const auto file = [&](const std::string& name, const std::string& at) {
      f.path[name] = f.dir + "/" + at;
      f.read[name] = f.dir + "/" + at;
    };
    fs::copy_file(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml", f.dir + "/station.yaml");
    file("scenario", "station.yaml");
    write_file(f.dir + "/day.yaml", "base: station.yaml\nname: day\nseed: 3\n");
    file("day", "day.yaml");
    write_file(f.dir + "/campaign.yaml",
               "name: c\nsessions:\n  - {name: a, scenario: " + f.dir + "/day.yaml, mode: map}\n");
    file("campaign", "campaign.yaml");
    fs::copy(test::shared_path("data/tum/fr1_xyz_pair"), f.dir + "/seq", fs::copy_options::recursive);
    f.path["seq"] = f.dir + "/seq";
    f.read["seq"] = f.dir + "/seq/rgb.txt";
    fs::copy_file(test::shared_path("data/tum/TUM1.yaml"), f.dir + "/TUM1.yaml");
    file("settings", "TUM1.yaml");
    for (const char* img : {"img1.ppm", "img2.ppm", "H1to2p"})
      fs::copy_file(test::shared_path(std::string("data/oxford/wall/") + img), f.dir + "/" + img);
    file("img1", "img1.ppm");
    file("img2", "img2.ppm");
    file("homography", "H1to2p");
    fs::copy_file(f.dir + "/img1.ppm", f.dir + "/images/a.ppm");
    f.path["images"] = f.dir + "/images";
    f.read["images"] = f.dir + "/images/a.ppm";
    const std::string traj = "1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0 1\n3.0 2 0 0 0 0 0 1\n";
    write_file(f.dir + "/gt.txt", traj);
    file("gt", "gt.txt");
    write_file(f.dir + "/est.txt", traj);
    file("est", "est.txt");
    write_file(f.dir + "/map.pvbmap", "not read: the refusal comes first");
    file("map", "map.pvbmap");
    write_file(f.dir + "/cloud.ply", "not read either");
    file("cloud", "cloud.ply");
    return f;
  }();
  return in;
}

/// A command: its arguments with {name} for each input, and its outputs
/// (`--opt` a file, `--opt/` a folder; the folder ones get --overwrite).
struct Command {
  std::string args;
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
};

const std::vector<Command>& commands() {
  static const std::vector<Command> c = {
      {"record --scenario {scenario}", {"scenario"}, {"--out/"}},
      {"run --scenario {day} --map {map} --map-mode extend", {"day", "scenario", "map"}, {"--out/", "--save-map"}},
      {"slam --sequence {seq} --settings {settings} --map {map} --map-mode extend",
       {"seq", "settings", "map"},
       {"--out/", "--save-map"}},
      {"camera --uri sim://{scenario} --settings {settings} --map {map} --map-mode extend",
       {"scenario", "settings", "map"},
       {"--out/", "--save-map", "--record"}},
      {"eval --gt {gt} --est {est}", {"gt", "est"}, {"--json", "--plot"}},
      {"eval-map --map {cloud} --scenario {scenario} --trajectory {est} --gt {gt}",
       {"cloud", "scenario", "est", "gt"},
       {"--out/"}},
      {"match --img1 {img1} --img2 {img2} --homography {homography} --runs 1",
       {"img1", "img2", "homography"},
       {"--json", "--draw"}},
      {"match --sequence {seq} --frames 0,1 --settings {settings} --runs 1", {"seq", "settings"}, {"--json", "--draw"}},
      {"vocab --scenario {scenario} --sequence {seq} --images {images}", {"scenario", "seq", "images"}, {"--out"}},
      {"sheet --scenario {scenario}", {"scenario"}, {"--out"}},
      {"plan --scenario {scenario}", {"scenario"}, {"--out"}},
      {"campaign --campaign {campaign}", {"campaign", "day", "scenario"}, {"--out/"}},
      {"sweep --scenario {day} --seeds 1", {"day", "scenario"}, {"--out/"}},
      {"sweep --campaign {campaign} --seeds 1", {"campaign", "day"}, {"--out/"}},
  };
  return c;
}

/// `args` with every {name} replaced by `path`.
std::string replace_key(std::string args, const std::string& name, const std::string& path) {
  const std::string key = "{" + name + "}";
  for (std::size_t at; (at = args.find(key)) != std::string::npos;) args.replace(at, key.size(), path);
  return args;
}

/// `args` with each {name} replaced by the input's own path.
std::string expand(std::string args) {
  for (const auto& [name, path] : inputs().path) args = replace_key(args, name, path);
  return args;
}

/// An earlier pvbench output folder (it holds the marker) with a copy of
/// input `name` in it.
std::string folder_holding(const std::string& name) {
  static int n = 0;
  const InputFiles& in = inputs();
  const std::string out = in.dir + "/out_" + std::to_string(n++);
  fs::create_directories(out);
  write_file(out + "/.pvbench", "written by pvbench run\n");
  const std::string copy = out + "/" + fs::path(in.path.at(name)).filename().string();
  fs::copy(in.path.at(name), copy, fs::copy_options::recursive);
  if (name == "day" || name == "scenario") {  // a day file and its base travel together
    fs::copy_file(in.path.at("day"), out + "/day.yaml", fs::copy_options::overwrite_existing);
    fs::copy_file(in.path.at("scenario"), out + "/station.yaml", fs::copy_options::overwrite_existing);
  }
  return out;
}

/// One case: the command line, the file that must stay unchanged, and
/// what the error line must begin with.
struct Case {
  std::string args, kept, says;
};

/// `output` of `c` pointed at `input`.
Case case_of(const Command& c, const std::string& input, const std::string& output, int k) {
  const InputFiles& in = inputs();
  if (output.back() != '/') {
    std::string args = expand(c.args) + " " + output + " " + in.read.at(input);
    if (c.outputs.front() == "--out/") args += " --out " + in.dir + "/fresh_" + std::to_string(k);
    return {args, in.read.at(input), in.read.at(input) + ": "};
  }
  // A folder output that holds the input: the command names the copies.
  const std::string out = folder_holding(input);
  std::map<std::string, std::string> moved;
  for (const auto& [name, path] : in.path)
    if (fs::exists(out + "/" + fs::path(path).filename().string()))
      moved[name] = out + "/" + fs::path(path).filename().string();
  if (c.args.find("{campaign}") != std::string::npos && moved.count("day")) {
    moved["campaign"] = in.dir + "/campaign_" + std::to_string(k) + ".yaml";
    write_file(moved["campaign"], "name: c\nsessions:\n  - {name: a, scenario: " + moved["day"] + ", mode: map}\n");
  }
  std::string args = c.args;
  for (const auto& [name, path] : moved) args = replace_key(args, name, path);
  const std::string kept = out + "/" + fs::relative(in.read.at(input), in.dir).string();
  return {expand(args) + " " + output.substr(0, output.size() - 1) + " " + out + " --overwrite", kept,
          out + ": the "};
}

}  // namespace

TEST(OutputsOnInputs, EveryOutputOfEveryCommandOnEachOfItsInputsIsRefused) {
  const bool camera = test::run_pvbench("camera --help").code == 0;  // built with OpenNI2
  int k = 0;
  for (const Command& c : commands()) {
    if (!camera && c.args.rfind("camera", 0) == 0) continue;
    for (const std::string& output : c.outputs)
      for (const std::string& input : c.inputs) {
        const Case t = case_of(c, input, output, k++);
        SCOPED_TRACE(t.args);
        const std::string before = read_file(t.kept);
        const test::RunResult r = test::run_pvbench_from_source("", t.args);
        EXPECT_EQ(r.code, 1) << r.output;
        EXPECT_EQ(r.output.find("pvbench: error: "), r.output.rfind("pvbench: error: ")) << r.output;
        EXPECT_NE(r.output.find("pvbench: error: " + t.says), std::string::npos) << r.output;
        EXPECT_EQ(read_file(t.kept), before) << t.kept << " changed";
      }
  }
  EXPECT_GE(k, camera ? 45 : 36);
}

TEST(OutputsOnInputs, TwoOutputsOnOneFileAndAnAggregateOnItsScenarioAreRefused) {
  const InputFiles& in = inputs();
  test::RunResult r = test::run_pvbench(expand("eval --gt {gt} --est {est} --json " + in.dir + "/x --plot " +
                                               in.dir + "/x"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("--json and --plot name the same file"), std::string::npos) << r.output;
  // --aggregate-only writes aggregate.md into --out: a scenario of that name there stays.
  const std::string agg = in.dir + "/agg";
  fs::create_directories(agg);
  fs::copy_file(in.path.at("scenario"), agg + "/aggregate.md", fs::copy_options::overwrite_existing);
  const std::string before = read_file(agg + "/aggregate.md");
  r = test::run_pvbench("sweep --scenario " + agg + "/aggregate.md --aggregate-only --out " + agg + " --seeds 1");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find(agg + "/aggregate.md: is the --scenario file, an input of this command"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(read_file(agg + "/aggregate.md"), before);
}

TEST(OutputsOnInputs, AnEmptyOutputPathIsAnErrorNotNoOutput) {
  const InputFiles& in = inputs();
  const test::RunResult r =
      test::run_pvbench(expand("run --scenario {scenario} --out " + in.dir + "/e1 --save-map ''"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("pvbench run: --save-map: expected a path, got an empty one"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(in.dir + "/e1"));
}

TEST(OutputsOnInputs, AMapIntoAMissingFolderOrOntoAFolderIsRefusedBeforeTheRun) {
  const InputFiles& in = inputs();
  for (const auto& [save, says] : std::vector<std::pair<std::string, std::string>>{
           {in.dir + "/missing/m.pvbmap", "the folder " + in.dir + "/missing does not exist"},
           {in.dir + "/images", "the --save-map output is a folder"}}) {
    const test::RunResult r =
        test::run_pvbench(expand("run --scenario {scenario} --out " + in.dir + "/f1 --save-map " + save));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(in.dir + "/f1")) << "the run began";
  }
}

TEST(OutputsOnInputs, ABadMapLeavesNoOutputFolder) {
  // The map is read (and refused) before the folder is made, so the same
  // command with a good map needs no --overwrite.
  const InputFiles& in = inputs();
  const std::string out = in.dir + "/badmap";
  const test::RunResult r =
      test::run_pvbench(expand("run --scenario {scenario} --out " + out + " --map {map} --map-mode localise"));
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find(in.path.at("map") + ": "), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out)) << "the run made its folder before it read the map";
}
