// Agreement with the TUM RGB-D benchmark scripts.  data/tum_reference.py
// generated ref_gt.txt / ref_est.txt and computed ref_expected.txt with an
// independent plain-Python re-implementation of evaluate_ate.py (Horn's
// quaternion method) and evaluate_rpe.py --fixed_delta; see
// docs/evaluation.md.  The estimate has jittered stamps, dropped frames, a
// rigid offset, drift and noise.
#include <gtest/gtest.h>

#include <map>
#include <sstream>

#include "pvb/common/text.hpp"
#include "pvb/eval/evaluate.hpp"

using namespace pvb;
using namespace pvb::eval;

namespace {
const std::string kData = std::string(PVB_SOURCE_DIR) + "/tests/harness/eval/data/";

std::map<std::string, std::vector<double>> read_expected() {
  std::map<std::string, std::vector<double>> out;
  std::istringstream in(read_file(kData + "ref_expected.txt"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    double v;
    while (ls >> v) out[key].push_back(v);
  }
  return out;
}

void expect_stats(const std::map<std::string, std::vector<double>>& ex, const std::string& prefix, const Stats& s,
                  double tol) {
  ASSERT_TRUE(ex.count(prefix + ".rmse")) << prefix;
  EXPECT_NEAR(s.rmse, ex.at(prefix + ".rmse")[0], tol) << prefix;
  EXPECT_NEAR(s.mean, ex.at(prefix + ".mean")[0], tol) << prefix;
  EXPECT_NEAR(s.median, ex.at(prefix + ".median")[0], tol) << prefix;
  EXPECT_NEAR(s.std, ex.at(prefix + ".std")[0], tol) << prefix;
  EXPECT_NEAR(s.min, ex.at(prefix + ".min")[0], tol) << prefix;
  EXPECT_NEAR(s.max, ex.at(prefix + ".max")[0], tol) << prefix;
}
}  // namespace

TEST(TumAgreement, AteMatchesEvaluateAte) {
  const auto ex = read_expected();
  const Trajectory gt = read_tum(kData + "ref_gt.txt");
  const Trajectory est = read_tum(kData + "ref_est.txt");
  const EvalResult r = evaluate(gt, est, {});
  EXPECT_EQ(static_cast<double>(r.pairs.size()), ex.at("pairs")[0]);
  expect_stats(ex, "ate", r.ate, 1e-9);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(r.alignment.R(i, j), ex.at("alignment.R" + std::to_string(i))[j], 1e-9);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.alignment.t(i), ex.at("alignment.t")[i], 1e-9);
}

TEST(TumAgreement, RpeMatchesEvaluateRpeFixedDelta) {
  const auto ex = read_expected();
  const Trajectory gt = read_tum(kData + "ref_gt.txt");
  const Trajectory est = read_tum(kData + "ref_est.txt");
  const struct {
    double delta;
    DeltaUnit unit;
    const char* name;
  } cases[] = {{1, DeltaUnit::kFrames, "rpe.1f"},
               {5, DeltaUnit::kFrames, "rpe.5f"},
               {0.5, DeltaUnit::kSeconds, "rpe.0.5s"},
               {1.0, DeltaUnit::kMetres, "rpe.1m"}};
  for (const auto& c : cases) {
    EvalOptions o;
    o.rpe.delta = c.delta;
    o.rpe.unit = c.unit;
    const EvalResult r = evaluate(gt, est, o);
    EXPECT_EQ(static_cast<double>(r.rpe_trans_m.count), ex.at(std::string(c.name) + ".count")[0]) << c.name;
    expect_stats(ex, std::string(c.name) + ".trans", r.rpe_trans_m, 1e-9);
    expect_stats(ex, std::string(c.name) + ".rot_deg", r.rpe_rot_deg, 1e-7);
  }
}
