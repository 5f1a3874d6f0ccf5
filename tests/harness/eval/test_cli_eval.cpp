// Runs the built pvbench binary on small files.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <vector>

#include "pvb/common/text.hpp"

namespace {
const std::string kBin = std::string(PVB_BINARY_DIR) + "/bin/pvbench";

std::string temp_dir() {
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("pvb_cli_eval_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// Runs pvbench with `args`; returns the exit code, stderr in *err.
int run(const std::string& args, std::string* err = nullptr) {
  const std::string err_path = temp_dir() + "/stderr.txt";
  const int status = std::system((kBin + " " + args + " > /dev/null 2> " + err_path).c_str());
  if (err) *err = pvb::read_file(err_path);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string tum_loop(double noise_m, double t0_s, int n = 60) {
  std::string out = "# t tx ty tz qx qy qz qw\n";
  char buf[200];
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f %.6f 0 0 %.6f %.6f\n", t0_s + 0.1 * i,
                  4 * std::cos(a) + noise_m * ((i % 2) ? 1 : -1), 3 * std::sin(a), 0.3 * std::sin(2 * a),
                  std::sin(a / 2), std::cos(a / 2));
    out += buf;
  }
  return out;
}
}  // namespace

TEST(CliEval, WritesJsonAndPlots) {
  const std::string d = temp_dir();
  pvb::write_file(d + "/gt.txt", tum_loop(0.0, 10.0));
  pvb::write_file(d + "/a.txt", tum_loop(0.05, 10.0));
  pvb::write_file(d + "/b.txt", tum_loop(0.02, 10.0));
  ASSERT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/a.txt --est " + d + "/b.txt --json " + d +
                "/out.json --plot " + d + "/plot.svg --delta 2 --delta-unit f"),
            0);
  const std::string json = pvb::read_file(d + "/out.json");
  for (const char* key : {"\"ate\"", "\"rpe\"", "\"trans\"", "\"rot_deg\"", "\"pairs\": 60", "\"alignment\"", "\"runs\"",
                          "\"reduction_percent\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  EXPECT_TRUE(std::filesystem::file_size(d + "/plot.svg") > 1000);
  EXPECT_TRUE(std::filesystem::file_size(d + "/plot.png") > 1000);
  EXPECT_TRUE(std::filesystem::exists(d + "/plot_2.svg"));
  EXPECT_TRUE(std::filesystem::exists(d + "/plot_2.png"));
}

TEST(CliEval, ErrorsGiveOneLineAndNonZeroExit) {
  const std::string d = temp_dir();
  pvb::write_file(d + "/gt.txt", tum_loop(0.0, 10.0));
  pvb::write_file(d + "/bad.txt", "# header\n1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 1\n");
  pvb::write_file(d + "/empty.txt", "");
  pvb::write_file(d + "/late.txt", tum_loop(0.0, 5000.0));
  std::string err;
  EXPECT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/bad.txt", &err), 1);
  EXPECT_NE(err.find(d + "/bad.txt:3:"), std::string::npos) << err;
  EXPECT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/empty.txt", &err), 1);
  EXPECT_NE(err.find("empty"), std::string::npos) << err;
  EXPECT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/late.txt", &err), 1);
  EXPECT_NE(err.find("--offset"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  // The same files associate with the right offset.
  EXPECT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/late.txt --offset -4990", &err), 0) << err;
  EXPECT_NE(run("eval --gt " + d + "/gt.txt --est " + d + "/gt.txt --align bogus", &err), 0);
}

// A folder given as --gt, an absurd estimated position and out-of-range
// association options are each one clear error line.
TEST(CliEval, FolderAbsurdPositionAndBadOptionsAreOneLineEach) {
  const std::string d = temp_dir();
  pvb::write_file(d + "/gt.txt", tum_loop(0.0, 10.0));
  std::string far;  // the loop with x = 1e300 on line 6
  std::istringstream loop(tum_loop(0.0, 10.0));
  int number = 1;
  for (std::string line; std::getline(loop, line); ++number) {
    std::vector<std::string> f = pvb::split_ws(line);
    if (number == 6) f[1] = "1e300";
    for (const std::string& field : f) far += field + " ";
    far.back() = '\n';
  }
  pvb::write_file(d + "/far.txt", far);
  std::string err;
  EXPECT_EQ(run("eval --gt " + d + " --est " + d + "/gt.txt", &err), 1);
  EXPECT_NE(err.find(d + ": is a folder, not a file"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  EXPECT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/far.txt", &err), 1);
  EXPECT_NE(err.find(d + "/far.txt:6: position (1e300 "), std::string::npos) << err;
  EXPECT_EQ(err.find("same point"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  for (const std::string bad :
       {"--max-diff 1e30", "--max-diff nan", "--offset 1e300", "--offset nan", "--delta inf"}) {
    EXPECT_EQ(run("eval --gt " + d + "/gt.txt --est " + d + "/gt.txt " + bad, &err), 1) << bad;
    EXPECT_NE(err.find("command line: " + bad.substr(0, bad.find(' '))), std::string::npos) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  }
}
