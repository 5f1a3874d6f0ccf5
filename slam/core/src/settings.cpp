#include "pvb/slam/core/settings.hpp"

#include <fstream>
#include <opencv2/core.hpp>
#include <set>

#include "pvb/common/error.hpp"

namespace pvb::slam {
namespace {

class Reader {
 public:
  Reader(const cv::FileStorage& fs, std::string path) : fs_(fs), path_(std::move(path)) {}

  double real(const std::string& key, bool required, double fallback) {
    seen_.insert(key);
    const cv::FileNode n = fs_[key];
    if (n.empty()) {
      if (required) throw ConfigError(path_, key, "a number (required key is missing)");
      return fallback;
    }
    if (!n.isReal() && !n.isInt()) throw ConfigError(path_, key, "a number");
    return static_cast<double>(n);
  }
  int integer(const std::string& key, bool required, int fallback) {
    const double v = real(key, required, fallback);
    if (v != static_cast<double>(static_cast<int>(v))) throw ConfigError(path_, key, "an integer", std::to_string(v));
    return static_cast<int>(v);
  }
  bool flag(const std::string& key, bool fallback) {
    const int v = integer(key, false, fallback ? 1 : 0);
    if (v != 0 && v != 1) throw ConfigError(path_, key, "0 or 1", std::to_string(v));
    return v == 1;
  }
  void positive(const std::string& key, double v) {
    if (!(v > 0)) throw ConfigError(path_, key, "a positive value", std::to_string(v));
  }
  const std::set<std::string>& seen() const { return seen_; }

 private:
  const cv::FileStorage& fs_;
  std::string path_;
  std::set<std::string> seen_;
};

// Keys ORB-SLAM2 files carry that the RGB-D core does not use.
bool ignored_key(const std::string& key) {
  return key.rfind("Viewer.", 0) == 0 || key == "Camera.type" || key == "Camera.bFishEye";
}

}  // namespace

Settings read_settings(const std::string& path) {
  if (!std::ifstream(path)) throw IoError(path, "cannot open settings file");
  cv::FileStorage fs;
  try {
    if (!fs.open(path, cv::FileStorage::READ)) throw IoError(path, "cannot open settings file");
  } catch (const cv::Exception& e) {
    throw IoError(path, std::string("cannot parse settings file: ") + e.err);
  }
  Settings s;
  s.source = path;
  Reader r(fs, path);
  s.K.fx = r.real("Camera.fx", true, 0);
  s.K.fy = r.real("Camera.fy", true, 0);
  s.K.cx = r.real("Camera.cx", true, 0);
  s.K.cy = r.real("Camera.cy", true, 0);
  r.positive("Camera.fx", s.K.fx);
  r.positive("Camera.fy", s.K.fy);
  s.k1 = r.real("Camera.k1", true, 0);
  s.k2 = r.real("Camera.k2", true, 0);
  s.p1 = r.real("Camera.p1", true, 0);
  s.p2 = r.real("Camera.p2", true, 0);
  s.k3 = r.real("Camera.k3", false, 0);  // optional in ORB-SLAM2 too
  s.K.width = r.integer("Camera.width", true, 0);
  s.K.height = r.integer("Camera.height", true, 0);
  r.positive("Camera.width", s.K.width);
  r.positive("Camera.height", s.K.height);
  s.fps = r.real("Camera.fps", true, 30);
  r.positive("Camera.fps", s.fps);
  s.bf = r.real("Camera.bf", true, 0);
  r.positive("Camera.bf", s.bf);
  s.rgb_order = r.flag("Camera.RGB", true);
  if (fs["Camera.RGB"].empty()) throw ConfigError(path, "Camera.RGB", "0 or 1 (required key is missing)");
  s.th_depth = r.real("ThDepth", true, 0);
  r.positive("ThDepth", s.th_depth);
  s.depth_map_factor = r.real("DepthMapFactor", true, 0);
  r.positive("DepthMapFactor", s.depth_map_factor);
  s.orb.num_features = r.integer("ORBextractor.nFeatures", true, 0);
  s.orb.scale_factor = r.real("ORBextractor.scaleFactor", true, 0);
  s.orb.num_levels = r.integer("ORBextractor.nLevels", true, 0);
  s.orb.ini_fast_threshold = r.integer("ORBextractor.iniThFAST", true, 0);
  s.orb.min_fast_threshold = r.integer("ORBextractor.minThFAST", true, 0);
  s.orb.sub_pixel = r.flag("ORBextractor.subPixel", s.orb.sub_pixel);  // ours, optional
  s.align_patches = r.flag("Tracking.alignPatches", s.align_patches);   // ours, optional
  r.positive("ORBextractor.nFeatures", s.orb.num_features);
  if (!(s.orb.scale_factor > 1.0))
    throw ConfigError(path, "ORBextractor.scaleFactor", "a value > 1", std::to_string(s.orb.scale_factor));
  r.positive("ORBextractor.nLevels", s.orb.num_levels);

  PeMatchSettings& pe = s.pe_match;
  pe.enabled = r.flag("PEMatch.enabled", pe.enabled);
  pe.population = r.integer("PEMatch.population", false, pe.population);
  pe.num_fitness_samples = r.integer("PEMatch.j", false, pe.num_fitness_samples);
  pe.stall_iterations = r.integer("PEMatch.stallIterations", false, pe.stall_iterations);
  pe.threshold_px = r.real("PEMatch.threshold", false, pe.threshold_px);
  pe.refine = r.flag("PEMatch.refine", pe.refine);
  pe.sampson = r.flag("PEMatch.sampson", pe.sampson);
  pe.skip_low_parallax = r.flag("PEMatch.skipLowParallax", pe.skip_low_parallax);
  if (pe.population < 2) throw ConfigError(path, "PEMatch.population", "an integer >= 2");
  r.positive("PEMatch.j", pe.num_fitness_samples);
  r.positive("PEMatch.stallIterations", pe.stall_iterations);
  r.positive("PEMatch.threshold", pe.threshold_px);

  KeyFrameSettings& kfs = s.keyframe;
  kfs.min_tracked_close = r.integer("KeyFrame.minTrackedClose", false, kfs.min_tracked_close);
  kfs.min_untracked_close = r.integer("KeyFrame.minUntrackedClose", false, kfs.min_untracked_close);
  r.positive("KeyFrame.minTrackedClose", kfs.min_tracked_close);
  r.positive("KeyFrame.minUntrackedClose", kfs.min_untracked_close);
  kfs.ref_overlap = r.real("KeyFrame.refOverlap", false, kfs.ref_overlap);
  if (!(kfs.ref_overlap >= 0.0 && kfs.ref_overlap < 1.0))
    throw ConfigError(path, "KeyFrame.refOverlap", "a number in [0, 1) (0: ORB-SLAM2's rule)",
                      std::to_string(kfs.ref_overlap));

  PointCloudMappingSettings& pc = s.dense;
  pc.enabled = r.flag("PointCloudMapping.Enabled", pc.enabled);
  pc.resolution_m = r.real("PointCloudMapping.Resolution", false, pc.resolution_m);
  pc.stride_px = r.integer("PointCloudMapping.Stride", false, pc.stride_px);
  pc.min_depth_m = r.real("PointCloudMapping.MinDepth", false, pc.min_depth_m);
  pc.max_depth_m = r.real("PointCloudMapping.MaxDepth", false, pc.max_depth_m);
  r.positive("PointCloudMapping.Resolution", pc.resolution_m);
  r.positive("PointCloudMapping.Stride", pc.stride_px);
  if (!(pc.min_depth_m >= 0))
    throw ConfigError(path, "PointCloudMapping.MinDepth", "a value >= 0", std::to_string(pc.min_depth_m));
  if (!(pc.max_depth_m > pc.min_depth_m))
    throw ConfigError(path, "PointCloudMapping.MaxDepth", "a value > PointCloudMapping.MinDepth",
                      std::to_string(pc.max_depth_m));

  LoopClosingOptions& lc = s.loop;
  lc.enabled = r.flag("LoopClosing.enabled", lc.enabled);
  lc.search_radius_m = r.real("LoopClosing.searchRadius", false, lc.search_radius_m);
  lc.max_angle_deg = r.real("LoopClosing.maxAngle", false, lc.max_angle_deg);
  lc.min_keyframe_gap = r.integer("LoopClosing.minKeyFrameGap", false, lc.min_keyframe_gap);
  lc.max_candidates = r.integer("LoopClosing.maxCandidates", false, lc.max_candidates);
  lc.min_matches = r.integer("LoopClosing.minMatches", false, lc.min_matches);
  lc.consistency = r.integer("LoopClosing.consistency", false, lc.consistency);
  lc.min_inliers = r.integer("LoopClosing.minInliers", false, lc.min_inliers);
  lc.max_correction_m = r.real("LoopClosing.maxCorrection", false, lc.max_correction_m);
  lc.max_correction_deg = r.real("LoopClosing.maxCorrectionAngle", false, lc.max_correction_deg);
  lc.essential_weight = r.integer("LoopClosing.essentialWeight", false, lc.essential_weight);
  lc.global_ba = r.flag("LoopClosing.globalBA", lc.global_ba);
  lc.rotation_weight = r.real("LoopClosing.rotationWeight", false, lc.rotation_weight);
  r.positive("LoopClosing.rotationWeight", lc.rotation_weight);
  r.positive("LoopClosing.searchRadius", lc.search_radius_m);
  if (!(lc.max_angle_deg > 0 && lc.max_angle_deg <= 180))
    throw ConfigError(path, "LoopClosing.maxAngle", "a value in (0, 180]", std::to_string(lc.max_angle_deg));
  r.positive("LoopClosing.minKeyFrameGap", lc.min_keyframe_gap);
  r.positive("LoopClosing.maxCandidates", lc.max_candidates);
  if (lc.min_matches < 6) throw ConfigError(path, "LoopClosing.minMatches", "an integer >= 6", std::to_string(lc.min_matches));
  if (lc.consistency < 0) throw ConfigError(path, "LoopClosing.consistency", "an integer >= 0", std::to_string(lc.consistency));
  if (lc.min_inliers < 6) throw ConfigError(path, "LoopClosing.minInliers", "an integer >= 6", std::to_string(lc.min_inliers));
  r.positive("LoopClosing.maxCorrection", lc.max_correction_m);
  r.positive("LoopClosing.maxCorrectionAngle", lc.max_correction_deg);
  r.positive("LoopClosing.essentialWeight", lc.essential_weight);

  const cv::FileNode root = fs.root();
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = (*it).name();
    if (!r.seen().count(key) && !ignored_key(key)) s.warnings.push_back(path + ": unknown key '" + key + "' ignored");
  }
  return s;
}

}  // namespace pvb::slam
