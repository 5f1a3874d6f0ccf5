#include "pvb/harness/matching/experiment.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pvb/common/clock.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::harness {
namespace {

using Clock = std::chrono::steady_clock;


/// Keeps the matches within `threshold_px` (eq. 8) of F's epipolar lines.
std::vector<std::uint8_t> filter_by_F(const cv::Mat& Fcv, const std::vector<slam::PointMatch>& pts,
                                      double threshold_px) {
  std::vector<std::uint8_t> keep(pts.size(), 0);
  if (Fcv.rows != 3 || Fcv.cols != 3) return keep;  // no model (or several 7-point solutions)
  Eigen::Matrix3d F;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) F(r, c) = Fcv.at<double>(r, c);
  for (size_t i = 0; i < pts.size(); ++i)
    keep[i] = slam::within_epipolar_threshold(F, pts[i].p1, pts[i].p2, threshold_px) ? 1 : 0;
  return keep;
}

}  // namespace

const char* method_name(MatchMethod m) {
  switch (m) {
    case MatchMethod::kOrb: return "orb";
    case MatchMethod::kHamming: return "hamming";
    case MatchMethod::kRansac: return "ransac";
    case MatchMethod::kMagsac: return "magsac";
    case MatchMethod::kPe: return "pe";
    case MatchMethod::kPeRefined: return "pe-refined";
  }
  return "?";
}

std::vector<MatchMethod> all_methods() {
  return {MatchMethod::kOrb, MatchMethod::kHamming, MatchMethod::kRansac,
          MatchMethod::kMagsac, MatchMethod::kPe, MatchMethod::kPeRefined};
}

std::vector<MatchMethod> parse_methods(const std::string& s) {
  if (s == "all") return all_methods();
  std::vector<MatchMethod> out;
  for (const std::string& name : split_ws(s, ",")) {
    bool found = false;
    for (MatchMethod m : all_methods())
      if (name == method_name(m)) {
        out.push_back(m);
        found = true;
      }
    if (!found) throw ConfigError("<command line>", "--method", "all|orb|hamming|ransac|magsac|pe|pe-refined", name);
  }
  return out;
}

void check_image_size(const cv::Mat& image, const std::string& path) {
  if (image.cols >= kMinImageSidePx && image.rows >= kMinImageSidePx) return;
  throw IoError(path, "image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                          " pixels; the matching experiment needs at least " +
                          std::to_string(kMinImageSidePx) + "x" + std::to_string(kMinImageSidePx));
}

CoarseSet make_coarse_set(const cv::Mat& img1, const cv::Mat& img2, double ratio) {
  for (const cv::Mat* image : {&img1, &img2})
    if (image->cols < kMinImageSidePx || image->rows < kMinImageSidePx)
      throw Error("make_coarse_set: an image is smaller than " + std::to_string(kMinImageSidePx) +
                  " px on a side");
  CoarseSet cs;
  slam::OrbExtractor ex;
  const auto t0 = Clock::now();
  cs.f1 = ex.extract(img1);
  cs.f2 = ex.extract(img2);
  cs.matches = slam::match_hamming_ratio(cs.f1, cs.f2, ratio);
  cs.extract_match_ms = ms_since(t0);
  for (const auto& m : cs.matches) {
    const cv::Point2f a = cs.f1.keypoints[m.i1].pt, b = cs.f2.keypoints[m.i2].pt;
    cs.raw.push_back({{a.x, a.y}, {b.x, b.y}});
  }
  cs.points = cs.raw;
  return cs;
}

std::vector<std::uint8_t> run_method(MatchMethod m, const CoarseSet& cs, unsigned seed,
                                     const slam::PeMatchParams& pe_params, slam::PeMatcher& pe) {
  const size_t n = cs.points.size();
  constexpr double kThresholdPx = 3.0;  // paper sec. 5.1.2, all F-based methods
  switch (m) {
    case MatchMethod::kOrb:
      return std::vector<std::uint8_t>(n, 1);
    case MatchMethod::kHamming: {
      // ORB+HAMMING: drop matches with distance > max(2 * min distance, 30).
      int min_d = 256;
      for (const auto& fm : cs.matches) min_d = std::min(min_d, fm.distance);
      const int limit = std::max(2 * min_d, 30);
      std::vector<std::uint8_t> keep(n);
      for (size_t i = 0; i < n; ++i) keep[i] = cs.matches[i].distance <= limit;
      return keep;
    }
    case MatchMethod::kRansac:
    case MatchMethod::kMagsac: {
      if (n < 8) return std::vector<std::uint8_t>(n, 0);
      std::vector<cv::Point2d> a(n), b(n);
      for (size_t i = 0; i < n; ++i) {
        a[i] = {cs.points[i].p1.x(), cs.points[i].p1.y()};
        b[i] = {cs.points[i].p2.x(), cs.points[i].p2.y()};
      }
      cv::setRNGSeed(static_cast<int>(seed));
      cv::Mat F;
      if (m == MatchMethod::kRansac) {
        F = cv::findFundamentalMat(a, b, cv::FM_RANSAC, kThresholdPx, 0.99);
      } else {
        cv::UsacParams up;
        up.sampler = cv::SAMPLING_UNIFORM;
        up.score = cv::SCORE_METHOD_MAGSAC;
        up.loMethod = cv::LOCAL_OPTIM_SIGMA;
        up.threshold = kThresholdPx;
        up.confidence = 0.99;
        up.maxIterations = 5000;
        up.randomGeneratorState = static_cast<int>(seed);
        up.isParallel = false;
        try {
          cv::Mat mask;
          F = cv::findFundamentalMat(a, b, mask, up);
        } catch (const cv::Exception&) {
          F.release();  // no model
        }
      }
      // Paper sec. 5.1.2: with the fitted F, eliminate mismatches by the
      // epipolar distance (eq. 8) with the common threshold of 3 px.
      return filter_by_F(F, cs.points, kThresholdPx);
    }
    case MatchMethod::kPe:
    case MatchMethod::kPeRefined: {
      pe.params() = pe_params;
      pe.params().seed = seed;
      pe.params().refine = (m == MatchMethod::kPeRefined);
      slam::PeMatchResult r;
      pe.match(cs.points.data(), n, r);
      return r.inlier_mask;
    }
  }
  return {};
}

RunScore score_mask(const std::vector<std::uint8_t>& keep, const std::vector<MatchLabel>& labels) {
  int kept = 0, correct_kept = 0, correct = 0;
  for (size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] == MatchLabel::kUnknown) continue;
    const bool ok = labels[i] == MatchLabel::kCorrect;
    correct += ok;
    kept += keep[i] != 0;
    correct_kept += ok && keep[i];
  }
  RunScore s;
  s.kept = kept;
  s.precision = kept ? double(correct_kept) / kept : 0.0;
  s.recall = correct ? double(correct_kept) / correct : 0.0;
  return s;
}

Spread spread_of(const std::vector<double>& v) {
  Spread s;
  if (v.empty()) return s;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / v.size();
  double ss = 0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.std = v.size() > 1 ? std::sqrt(ss / (v.size() - 1)) : 0.0;
  return s;
}

std::vector<MethodReport> run_experiment(const CoarseSet& cs, const std::vector<MatchMethod>& methods, int runs,
                                         unsigned seed, const slam::PeMatchParams& pe_params) {
  std::vector<MethodReport> out;
  slam::PeMatcher pe(pe_params);
  // Warm-up so that the first timed PE call does not pay for buffer sizing.
  {
    slam::PeMatchResult r;
    pe.match(cs.points.data(), cs.points.size(), r);
  }
  int coarse = 0, coarse_correct = 0, unknown = 0;
  for (MatchLabel l : cs.labels) {
    unknown += l == MatchLabel::kUnknown;
    coarse += l != MatchLabel::kUnknown;
    coarse_correct += l == MatchLabel::kCorrect;
  }
  for (MatchMethod m : methods) {
    std::vector<double> prec, rec, kept, ms;
    for (int k = 0; k < runs; ++k) {
      const auto t0 = Clock::now();
      const std::vector<std::uint8_t> keep = run_method(m, cs, seed + k, pe_params, pe);
      const double t = ms_since(t0);
      const RunScore s = score_mask(keep, cs.labels);
      prec.push_back(s.precision);
      rec.push_back(s.recall);
      kept.push_back(s.kept);
      ms.push_back(t);
    }
    MethodReport r;
    r.name = method_name(m);
    r.precision = spread_of(prec);
    r.recall = spread_of(rec);
    r.kept = spread_of(kept);
    r.time_ms = spread_of(ms);
    r.coarse = coarse;
    r.coarse_correct = coarse_correct;
    r.unknown = unknown;
    r.runs = runs;
    out.push_back(r);
  }
  return out;
}

std::string reports_to_json(const std::vector<MethodReport>& reports, int runs, unsigned seed,
                            double extract_match_ms) {
  std::ostringstream o;
  o.precision(6);
  auto spread = [&](const char* key, const Spread& s) {
    o << "\"" << key << "\":" << s.mean << ",\"" << key << "_std\":" << s.std << ",\"" << key << "_min\":" << s.min
      << ",\"" << key << "_max\":" << s.max;
  };
  o << "{\"runs\":" << runs << ",\"seed\":" << seed << ",\"extract_match_ms\":" << extract_match_ms
    << ",\"methods\":[";
  for (size_t i = 0; i < reports.size(); ++i) {
    const MethodReport& r = reports[i];
    o << (i ? "," : "") << "{\"name\":\"" << json_escape(r.name) << "\",";
    spread("precision", r.precision);
    o << ",";
    spread("recall", r.recall);
    o << ",";
    spread("kept", r.kept);
    o << ",\"coarse\":" << r.coarse << ",\"coarse_correct\":" << r.coarse_correct << ",\"unknown\":" << r.unknown
      << ",";
    spread("time_ms", r.time_ms);
    o << "}";
  }
  o << "]}\n";
  return o.str();
}

cv::Mat draw_matches(const cv::Mat& img1, const cv::Mat& img2, const CoarseSet& cs,
                     const std::vector<std::uint8_t>& keep) {
  auto to_bgr = [](const cv::Mat& m) {
    cv::Mat c;
    if (m.channels() == 1)
      cv::cvtColor(m, c, cv::COLOR_GRAY2BGR);
    else
      c = m.clone();
    return c;
  };
  const cv::Mat a = to_bgr(img1), b = to_bgr(img2);
  cv::Mat canvas(std::max(a.rows, b.rows), a.cols + b.cols, CV_8UC3, cv::Scalar::all(0));
  a.copyTo(canvas(cv::Rect(0, 0, a.cols, a.rows)));
  b.copyTo(canvas(cv::Rect(a.cols, 0, b.cols, b.rows)));
  for (size_t i = 0; i < cs.raw.size() && i < keep.size(); ++i) {
    if (!keep[i]) continue;
    const cv::Scalar colour = cs.labels[i] == MatchLabel::kCorrect ? cv::Scalar(0, 200, 0)
                              : cs.labels[i] == MatchLabel::kWrong ? cv::Scalar(0, 0, 255)
                                                                   : cv::Scalar(0, 220, 220);
    const cv::Point p(cvRound(cs.raw[i].p1.x()), cvRound(cs.raw[i].p1.y()));
    const cv::Point q(cvRound(cs.raw[i].p2.x()) + a.cols, cvRound(cs.raw[i].p2.y()));
    cv::line(canvas, p, q, colour, 1, cv::LINE_AA);
    cv::circle(canvas, p, 2, colour, 1, cv::LINE_AA);
    cv::circle(canvas, q, 2, colour, 1, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace pvb::harness
