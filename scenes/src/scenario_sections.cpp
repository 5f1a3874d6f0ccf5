// The sections of a scenario file, one reader each, and the checks between
// them (scenes/SCHEMA.md).
#include "scenario_sections.hpp"

#include <algorithm>
#include <cmath>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/ground_relief.hpp"
#include "pvb/scenes/plant.hpp"
#include "pvb/scenes/route.hpp"

namespace pvb::scenes::detail {

/// The mount: fixed tables at tilt_deg with rails, or a single-axis tracker
/// whose angle follows the sun (tilt and rails are then not the file's to set).
void read_mount(MapReader& r, PvArray& a) {
  a.mount = r.choice<Mount>("mount", a.mount, {{"fixed", Mount::kFixed}, {"single_axis", Mount::kSingleAxis}});
  if (a.mount == Mount::kFixed) {
    if (r.has("tracker"))
      r.fail(r.full("tracker"), r.child("tracker"), "no tracker section unless mount is single_axis", "a tracker");
    a.tilt_deg = r.number("tilt_deg", a.tilt_deg, 0, 60);
    a.rails = r.boolean("rails", a.rails);
    return;
  }
  for (const char* key : {"tilt_deg", "rails"})
    if (r.has(key))
      r.fail(r.full(key), r.child(key), std::string("no ") + key + " for a single_axis mount (its panels turn on a "
                                        "torque tube; tracker.rotation_deg fixes their angle)", r.child(key).Scalar());
  a.tilt_deg = 0.0;
  a.rails = false;
  with_map(r, "tracker", [&](MapReader& t) {
    a.tracker.max_angle_deg = t.number("max_angle_deg", a.tracker.max_angle_deg, 1, 90);
    a.tracker.backtrack = t.boolean("backtrack", a.tracker.backtrack);
    if (t.has("rotation_deg")) {
      const double rot = t.number("rotation_deg", 0.0, -90, 90);
      if (std::abs(rot) > a.tracker.max_angle_deg)
        t.fail(t.full("rotation_deg"), t.child("rotation_deg"),
               "a rotation within the mount's limit of +-" + format_exact(a.tracker.max_angle_deg) + " deg",
               format_exact(rot));
      a.tracker.fixed_rotation_deg = rot;
    }
  });
}

namespace {

PvArray read_array(MapReader& r) {
  PvArray a;
  a.origin_m = r.vec2("origin_m", a.origin_m, -1e4, 1e4);
  a.azimuth_deg = r.number("azimuth_deg", a.azimuth_deg, -360, 360);
  a.rows = r.integer("rows", a.rows, 1, 50);
  a.tables_per_row = r.integer("tables_per_row", a.tables_per_row, 1, 50);
  a.panels_per_table = r.integer("panels_per_table", a.panels_per_table, 1, 60);
  a.panel_lines = r.integer("panel_lines", a.panel_lines, 1, 4);
  a.orientation = r.choice<PanelOrientation>(
      "orientation", a.orientation,
      {{"portrait", PanelOrientation::kPortrait}, {"landscape", PanelOrientation::kLandscape}});
  a.cells = r.integer("cells", a.cells, 60, 144);
  if (a.cells != 60 && a.cells != 72 && a.cells != 144)
    r.fail(r.full("cells"), YAML::Node(), "one of 60, 72, 144", std::to_string(a.cells));
  read_mount(r, a);
  a.table_gap_m = r.number("table_gap_m", a.table_gap_m, 0, 50);
  a.clearance_m = r.number("clearance_m", a.clearance_m, 0.1, 5);
  a.posts = r.boolean("posts", a.posts);
  a.dirt = r.number("dirt", a.dirt, 0, 1);
  a.specular_glass = r.choice<bool>("glass", a.specular_glass, {{"diffuse", false}, {"specular", true}});
  a.identical_tables = r.boolean("identical_tables", a.identical_tables);
  // The row's footprint (a tracker's when flat) and half a metre between rows.
  const double min_pitch = row_footprint_m(a) + 0.5;
  a.row_pitch_m = r.number("row_pitch_m", std::max(a.row_pitch_m, min_pitch), min_pitch, 100);
  return a;
}

}  // namespace

/// The sections of a scenario file, one reader each.
void read_arrays(MapReader& top, std::vector<PvArray>& out) {
  if (const YAML::Node arrays = top.child("pv_arrays")) {
    if (!arrays.IsSequence()) top.fail("pv_arrays", arrays, "a list of arrays");
    if (arrays.size() > static_cast<std::size_t>(kMaxListEntries))
      top.fail("pv_arrays", arrays, "at most " + std::to_string(kMaxListEntries) + " arrays in a file",
               std::to_string(arrays.size()));
    for (std::size_t i = 0; i < arrays.size(); ++i) {
      MapReader r(arrays[i], top.context(), "pv_arrays[" + std::to_string(i) + "]");
      out.push_back(read_array(r));
      r.finish();
    }
  }
}

void read_walls(MapReader& top, std::vector<Wall>& out) {
  if (const YAML::Node walls = top.child("walls")) {
    if (!walls.IsSequence()) top.fail("walls", walls, "a list of walls");
    if (walls.size() > static_cast<std::size_t>(kMaxListEntries))  // refused before reading them
      top.fail("walls", walls, "at most " + std::to_string(kMaxListEntries) + " walls in a file",
               std::to_string(walls.size()));
    for (std::size_t i = 0; i < walls.size(); ++i) {
      MapReader r(walls[i], top.context(), "walls[" + std::to_string(i) + "]");
      Wall w;
      w.start_m = r.vec2("start_m", w.start_m, -1e4, 1e4);
      w.end_m = r.vec2("end_m", w.end_m, -1e4, 1e4);
      w.height_m = r.number("height_m", w.height_m, 0.2, 10);
      w.thickness_m = r.number("thickness_m", w.thickness_m, 0.05, 2);
      w.finish = r.choice<WallFinish>("finish", w.finish,
                                      {{"brick", WallFinish::kBrick}, {"plaster", WallFinish::kPlaster}});
      if ((w.end_m - w.start_m).norm() < 0.2)
        r.fail(r.full("end_m"), walls[i]["end_m"], "an end at least 0.2 m from start_m");
      r.finish();
      out.push_back(w);
    }
  }
}

void read_vegetation(MapReader& r, Vegetation& v) {
  v.shrubs = r.integer("shrubs", v.shrubs, 0, 500);
  v.shrub_size_m = r.range("shrub_size_m", v.shrub_size_m, 0.05, 5);
  v.trees = r.integer("trees", v.trees, 0, 200);
  v.tree_height_m = r.range("tree_height_m", v.tree_height_m, 0.5, 30);
  const auto area = r.numbers("area_m", 4, -1e4, 1e4);
  if (!area.empty()) {
    v.area_m = Eigen::Vector4d(area[0], area[1], area[2], area[3]);
    if (area[0] >= area[2] || area[1] >= area[3])
      r.fail(r.full("area_m"), YAML::Node(), "[xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax");
  }
  v.keep_out_m = r.number("keep_out_m", v.keep_out_m, 0, 50);
  v.growth = r.number("growth", v.growth, 0.2, 2);
}

void read_light(MapReader& r, Light& l) {
  l.sun_azimuth_deg = r.number("sun_azimuth_deg", l.sun_azimuth_deg, -360, 360);
  l.sun_elevation_deg = r.number("sun_elevation_deg", l.sun_elevation_deg, 1, 90);
  l.intensity = r.number("intensity", l.intensity, 0, 1);
  l.ambient = r.number("ambient", l.ambient, 0, 1);
  l.shadows = r.boolean("shadows", l.shadows);
  l.shadow_map_px = r.integer("shadow_map_px", l.shadow_map_px, 256, 8192);
  l.shadow_follows_robot = r.boolean("shadow_follows_robot", l.shadow_follows_robot);
  l.box_quads = r.integer("box_quads", l.box_quads, 1, 16);
}

void read_route(MapReader& r, Route& rt) {
  rt.pattern = r.choice<RoutePattern>("pattern", rt.pattern,
                                      {{"waypoints", RoutePattern::kWaypoints},
                                       {"along_row", RoutePattern::kAlongRow},
                                       {"lawnmower", RoutePattern::kLawnmower},
                                       {"loop", RoutePattern::kLoop},
                                       {"roads", RoutePattern::kRoads}});
  if (const YAML::Node wps = r.child("waypoints_m")) {
    if (!wps.IsSequence() || wps.size() < 2)
      r.fail(r.full("waypoints_m"), wps, "a list of at least 2 [x, y] points");
    for (std::size_t i = 0; i < wps.size(); ++i) {
      double x = 0, y = 0;
      if (!wps[i].IsSequence() || wps[i].size() != 2 || !YAML::convert<double>::decode(wps[i][0], x) ||
          !YAML::convert<double>::decode(wps[i][1], y))
        r.fail(r.full("waypoints_m") + "[" + std::to_string(i) + "]", wps[i], "[x, y] in metres");
      rt.waypoints_m.emplace_back(x, y);
    }
  }
  rt.array = r.integer("array", rt.array, 0, 1000);
  rt.aisle = r.integer("aisle", rt.aisle, 0, 1000);
  rt.aisles = r.integer("aisles", rt.aisles, 1, 100);
  if (r.has("laps") && rt.pattern != RoutePattern::kLoop && rt.pattern != RoutePattern::kRoads)
    r.fail(r.full("laps"), r.child("laps"), "no laps unless route.pattern is loop or roads (it would be ignored)",
           r.child("laps").Scalar());
  rt.laps = r.integer("laps", rt.laps, 1, 100);
  if (r.has("block") && rt.pattern != RoutePattern::kRoads)
    r.fail(r.full("block"), r.child("block"), "no block unless route.pattern is roads (it would be ignored)",
           r.child("block").Scalar());
  rt.block = r.integer("block", rt.block, 1, 10000);
  for (const char* key : {"first_aisle", "from_dock"})
    if (r.has(key) && rt.pattern != RoutePattern::kLawnmower)
      r.fail(r.full(key), r.child(key), "no " + std::string(key) + " unless route.pattern is lawnmower (it would be ignored)",
             r.child(key).Scalar());
  rt.first_aisle = r.integer("first_aisle", rt.first_aisle, 0, 1000);
  rt.from_dock = r.boolean("from_dock", rt.from_dock);
  rt.return_to_start = r.boolean("return_to_start", rt.return_to_start);
  if (rt.from_dock && rt.return_to_start)
    r.fail(r.full("return_to_start"), r.child("return_to_start"),
           "false with route.from_dock (a route from the dock comes back to it)", "true");
  if (rt.return_to_start && rt.pattern != RoutePattern::kLawnmower)
    r.fail(r.full("return_to_start"), r.child("return_to_start"), "false unless route.pattern is lawnmower",
           "true");
  if (!rt.return_to_start && r.has("return_overlap_m"))
    r.fail(r.full("return_overlap_m"), r.child("return_overlap_m"),
           "no return_overlap_m unless route.return_to_start is true (it would be ignored)",
           r.child("return_overlap_m").Scalar());
  rt.return_overlap_m = r.number("return_overlap_m", rt.return_overlap_m, 0.5, 100);
  rt.offset_m = r.number("offset_m", rt.offset_m, 0.3, 20);
  rt.margin_m = r.number("margin_m", rt.margin_m, 0, 50);
  rt.speed_mps = r.number("speed_mps", rt.speed_mps, 0.05, 3);
  rt.lookahead_m = r.number("lookahead_m", rt.lookahead_m, 0.1, 5);
  rt.on_loss = r.choice<OnLoss>("on_loss", rt.on_loss, {{"wait", OnLoss::kWait}, {"abort", OnLoss::kAbort}});
  rt.start_m = r.number("start_m", rt.start_m, 0, 1e5);
}

void read_robot(MapReader& r, Robot& rb) {
  rb.wheel_radius_m = r.number("wheel_radius_m", rb.wheel_radius_m, 0.03, 0.5);
  rb.track_m = r.number("track_m", rb.track_m, 0.1, 2);
  rb.max_wheel_speed_radps = r.number("max_wheel_speed_radps", rb.max_wheel_speed_radps, 1, 100);
  if (r.has("max_wheel_accel_radps2"))
    rb.max_wheel_accel_radps2 = r.number("max_wheel_accel_radps2", 0, 0.1, 1000);
  rb.radius_error = r.number("radius_error", rb.radius_error, 0, 0.2);
  rb.track_error = r.number("track_error", rb.track_error, 0, 0.2);
  rb.radius_difference = r.number("radius_difference", rb.radius_difference, -0.05, 0.05);
}

/// The camera.stereo: section (the d435 model).
void read_stereo(MapReader& n, ActiveStereo& a) {
  a.ir_width = n.integer("ir_width", a.ir_width, 32, 4096);
  a.ir_height = n.integer("ir_height", a.ir_height, 32, 4096);
  a.ir_fx = n.number("ir_fx", a.ir_fx, 10, 1e5);
  a.baseline_m = n.number("baseline_m", a.baseline_m, 0.005, 1);
  a.colour_offset_m = n.number("colour_offset_m", a.colour_offset_m, -0.5, 0.5);
  a.projector_offset_m = n.number("projector_offset_m", a.projector_offset_m, -0.5, 0.5);
  a.projector_power_w = n.number("projector_power_w", a.projector_power_w, 0, 100);
  a.dots = n.integer("dots", a.dots, 0, 1000000);
  a.pattern_seed = static_cast<std::uint64_t>(n.integer("pattern_seed", static_cast<int>(a.pattern_seed), 0, 1 << 30));
  a.band_sun_w_m2 = n.number("band_sun_w_m2", a.band_sun_w_m2, 0, 1500);
  a.disparities = n.integer("disparities", a.disparities, 16, 512);
  if (a.disparities % 16 != 0) n.fail(n.full("disparities"), n.node()["disparities"], "a multiple of 16 (OpenCV's matcher)");
  a.block_px = n.integer("block_px", a.block_px, 3, 21);
  if (a.block_px % 2 == 0) n.fail(n.full("block_px"), n.node()["block_px"], "an odd number of pixels");
  a.uniqueness_pct = n.integer("uniqueness_pct", a.uniqueness_pct, 0, 100);
  a.ir_noise_sigma = n.number("ir_noise_sigma", a.ir_noise_sigma, 0, 50);
  // OpenCV's matcher searches that many pixels along each row: a range as
  // wide as the image makes it throw, or abort the process.
  if (a.disparities >= a.ir_width) {
    const std::string key = n.has("disparities") ? "disparities" : "ir_width";
    n.fail(n.full(key), n.child(key),
           "a disparity range narrower than the infrared image (disparities below ir_width; OpenCV's matcher "
           "searches within each row)",
           "disparities " + std::to_string(a.disparities) + ", ir_width " + std::to_string(a.ir_width));
  }
}

/// True when the camera's `section` was written in the file that chose its
/// model (or no file chose one).  A day file that makes its base's Kinect a
/// d435, or the other way round, leaves the base's section of the other
/// model unused; a file that writes both is refused.
bool written_with_the_model(const MapReader& r, const std::string& section) {
  if (!r.has("model")) return true;
  const auto file_of = [&r](const std::string& key) {
    const std::string where = r.context().where(r.full(key), r.node()[key]);
    return where.substr(0, where.rfind(':'));
  };
  return file_of("model") == file_of(section);
}

void read_camera(MapReader& r, Camera& c) {
  c.model = r.choice<CameraKind>("model", c.model, {{"kinect", CameraKind::kKinect}, {"d435", CameraKind::kD435}});
  if (c.model == CameraKind::kD435) c.use_d435_colour_camera();
  c.width = r.integer("width", c.width, 32, 4096);
  c.height = r.integer("height", c.height, 32, 4096);
  const bool has_fx = r.has("fx");
  c.fy = r.number("fy", c.fy, 10, 1e5);
  c.fx = r.number("fx", has_fx ? c.fx : c.fy, 10, 1e5);
  if (std::abs(c.fx - c.fy) > 1e-9)
    r.fail(r.full("fx"), YAML::Node(), "fx equal to fy (MuJoCo 2.2.2 renders square pixels)");
  c.fps = r.number("fps", c.fps, 1, 240);
  c.mount_height_m = r.number("mount_height_m", c.mount_height_m, 0.1, 5);
  c.mount_forward_m = r.number("mount_forward_m", c.mount_forward_m, -1, 1);
  c.pitch_deg = r.number("pitch_deg", c.pitch_deg, -89, 89);
  c.yaw_deg = r.number("yaw_deg", c.yaw_deg, -180, 180);
  c.depth_range_m = r.range("depth_range_m", c.depth_range_m, 0.05, 100);
  if (c.model == CameraKind::kD435 && r.has("depth_noise") && written_with_the_model(r, "depth_noise"))
    r.fail(r.full("depth_noise"), r.node()["depth_noise"],
           "no depth_noise: section unless model is kinect (a d435's depth comes from its stereo: section)");
  with_map(r, "depth_noise", [&](MapReader& n) {
    DepthNoise& d = c.depth_noise;
    d.model = n.choice<DepthNoiseModel>(
        "model", d.model, {{"none", DepthNoiseModel::kNone}, {"kinect", DepthNoiseModel::kKinect}});
    d.baseline_m = n.number("baseline_m", d.baseline_m, 0.01, 1);
    d.disparity_step_px = n.number("disparity_step_px", d.disparity_step_px, 0, 1);
    d.lateral_sigma_px = n.number("lateral_sigma_px", d.lateral_sigma_px, 0, 5);
    d.axial_scale = n.number("axial_scale", d.axial_scale, 0, 100);
    d.max_incidence_deg = n.number("max_incidence_deg", d.max_incidence_deg, 1, 90);
    d.sunlight.on = n.boolean("sunlight", d.sunlight.on);
    d.sunlight.filter_width_nm = n.number("sunlight_filter_nm", d.sunlight.filter_width_nm, 1, 100);
    d.sunlight.min_contrast = n.number("sunlight_min_contrast", d.sunlight.min_contrast, 1e-5, 1);
  });
  with_map(r, "stereo", [&](MapReader& n) { read_stereo(n, c.stereo); });
  if (c.model != CameraKind::kD435 && r.has("stereo") && written_with_the_model(r, "stereo"))
    r.fail(r.full("stereo"), r.node()["stereo"], "no stereo: section unless model is d435");
  with_map(r, "rgb", [&](MapReader& n) {
    RgbNoise& g = c.rgb;
    g.sigma = n.number("sigma", g.sigma, 0, 100);
    g.exposure = n.number("exposure", g.exposure, 0.05, 10);
    g.glare = n.number("glare", g.glare, 0, 1);
    g.auto_exposure = n.boolean("auto_exposure", g.auto_exposure);
  });
}

void read_slam(MapReader& r, SlamTuning& t) {
  t.orb_features = r.integer("orb_features", t.orb_features, 100, 20000);
  if (r.has("keyframe_min_tracked_close"))
    t.keyframe_min_tracked_close = r.integer("keyframe_min_tracked_close", 0, 1, 100000);
  if (r.has("keyframe_ref_overlap"))
    t.keyframe_ref_overlap = r.number("keyframe_ref_overlap", 0.0, 0.01, 0.99);
  if (r.has("sensors")) {
    std::vector<std::pair<std::string, sensor::SensorSetup>> setups;
    for (sensor::SensorSetup s : sensor::kSensorSetups) setups.emplace_back(sensor::to_string(s), s);
    t.sensors = r.choice("sensors", sensor::SensorSetup::kCamera, setups);
  }
}

void read_expect(MapReader& r, Expectations& e) {
  if (r.has("ate_rmse_m_max")) e.ate_rmse_m_max = r.number("ate_rmse_m_max", 0.0, 1e-6, 100);
  if (r.has("rpe_trans_rmse_m_max"))
    e.rpe_trans_rmse_m_max = r.number("rpe_trans_rmse_m_max", 0.0, 1e-6, 100);
  if (r.has("lost_frames_max")) e.lost_frames_max = r.integer("lost_frames_max", 0, 0, 1000000);
  if (r.has("keyframes_max")) e.keyframes_max = r.integer("keyframes_max", 0, 1, 1000000);
  if (r.has("refined_ate_rmse_m_max"))
    e.refined_ate_rmse_m_max = r.number("refined_ate_rmse_m_max", 0.0, 1e-6, 100);
  if (r.has("false_loops_max")) e.false_loops_max = r.integer("false_loops_max", 0, 0, 1000000);
  if (r.has("relocalised_within_frames"))
    e.relocalised_within_frames = r.integer("relocalised_within_frames", 0, 1, 1000000);
  if (r.has("loops_min")) e.loops_min = r.integer("loops_min", 0, 1, 1000000);
  if (r.has("map_accuracy_m_max")) e.map_accuracy_m_max = r.number("map_accuracy_m_max", 0.0, 1e-6, 100);
  if (r.has("map_completeness_min")) e.map_completeness_min = r.number("map_completeness_min", 0.0, 0.0, 1.0);
  e.blind_poses_all = r.boolean("blind_poses_all", e.blind_poses_all);
  if (r.has("blind_after_error_m_max"))
    e.blind_after_error_m_max = r.number("blind_after_error_m_max", 0.0, 1e-6, 100);
  if (r.has("blind_after_error_deg_max"))
    e.blind_after_error_deg_max = r.number("blind_after_error_deg_max", 0.0, 1e-6, 180);
  e.blind_no_global_relocalisation =
      r.boolean("blind_no_global_relocalisation", e.blind_no_global_relocalisation);
  if (r.has("pe_not_worse_than_baseline"))
    r.fail(r.full("pe_not_worse_than_baseline"), r.child("pe_not_worse_than_baseline"),
           "expect.sweep.pe_not_significantly_worse instead (PE-SLAM against the baseline is judged over "
           "a seed sweep, not one run; docs/scenarios.md)",
           "a single-run comparison");
  e.tracking_loss_expected = r.boolean("tracking_loss_expected", e.tracking_loss_expected);
  e.ci_frames = r.integer("ci_frames", e.ci_frames, 0, 1000000);
  if (e.ci_frames == 1)
    r.fail(r.full("ci_frames"), YAML::Node(), "0 (not in the fast subset) or at least 2 frames", "1");
  if (e.tracking_loss_expected && e.lost_frames_max == 0)
    r.fail(r.full("lost_frames_max"), YAML::Node(), "a value >= 1 when tracking_loss_expected is true", "0");
  with_map(r, "sweep", [&](MapReader& w) {
    SweepExpectations& sw = e.sweep;
    sw.pe_not_significantly_worse = w.boolean("pe_not_significantly_worse", sw.pe_not_significantly_worse);
    sw.min_seeds = w.integer("min_seeds", sw.min_seeds, 10, 100000);
  });
}

/// Where `key` of the map `n` is in the file (the map itself when the key is absent).
YAML::Node node_of(const YAML::Node& n, const char* key) {
  const YAML::Node& cn = n;  // const: operator[] must not insert the key
  const YAML::Node v = cn[key];
  return v.IsDefined() ? v : n;
}

namespace {

/// A covered lens's at_s and covered_s (of kidnap: or cover:).
Cover read_cover_times(MapReader& r) {
  Cover c;
  c.at_s = r.number("at_s", c.at_s, 0, kMaxScenarioTime_s);
  c.covered_s = r.number("covered_s", c.covered_s, 1e-3, 3600);
  return c;
}

/// The cover against the run: it starts before duration_s, lasts at least
/// one frame and ends before duration_s.
void check_cover_times(const MapReader& r, const YAML::Node& n, const Cover& c, const Scenario& s) {
  const double frame_s = 1.0 / s.camera.fps;
  const std::string one_frame =
      "at least one frame period (1 / camera.fps = " + format_number("%g", frame_s) + " s)";
  if (!(c.at_s < s.duration_s))
    r.fail(r.full("at_s"), node_of(n, "at_s"),
           "a time before duration_s (" + format_exact(s.duration_s) + " s)", format_exact(c.at_s));
  // At least one frame period (1e-9 s: a period written in decimals).
  if (c.covered_s < frame_s - 1e-9)
    r.fail(r.full("covered_s"), node_of(n, "covered_s"), one_frame, format_exact(c.covered_s));
  if (!(c.at_s + c.covered_s < s.duration_s))
    r.fail(r.full("covered_s"), node_of(n, "covered_s"),
           "at_s + covered_s before duration_s (" + format_exact(s.duration_s) + " s)",
           format_exact(c.at_s + c.covered_s) + " s");
  const CoverFrames f = cover_frames(c, s.camera.fps);
  if (f.end <= f.begin)
    r.fail(r.full("covered_s"), node_of(n, "covered_s"), one_frame, format_exact(c.covered_s));
}

}  // namespace

/// The kidnap: section.  Read after duration_s and camera, which bound it.
void read_kidnap(MapReader& top, Scenario& s) {
  const YAML::Node n = top.child("kidnap");
  if (!n) return;
  MapReader r(n, top.context(), "kidnap");
  for (const char* key : {"at_s", "to_route_s"})
    if (!r.has(key)) r.fail(r.full(key), n, "a time in seconds (required in kidnap)");
  const Cover c = read_cover_times(r);
  Kidnap k{c.at_s, c.covered_s, 0};
  k.to_route_s = r.number("to_route_s", k.to_route_s, 0, kMaxScenarioTime_s);
  r.finish();
  check_cover_times(r, n, c, s);
  const KidnapFrames f = kidnap_frames(k, s.camera.fps);
  if (!(k.to_route_s < k.at_s) || f.target >= f.cover_begin)
    r.fail(r.full("to_route_s"), node_of(n, "to_route_s"),
           "a time at least one frame before kidnap.at_s (" + format_exact(k.at_s) + " s)",
           format_exact(k.to_route_s));
  s.kidnap = k;
}

/// The cover: section.  Read after kidnap:, duration_s and camera.
void read_cover(MapReader& top, Scenario& s) {
  const YAML::Node n = top.child("cover");
  if (!n) return;
  MapReader r(n, top.context(), "cover");
  if (!r.has("at_s")) r.fail(r.full("at_s"), n, "a time in seconds (required in cover)");
  const Cover c = read_cover_times(r);
  r.finish();
  if (s.kidnap)
    r.fail("cover", n, "either kidnap or cover, not both (a kidnap covers the camera itself)",
           "both sections");
  check_cover_times(r, n, c, s);
  s.cover = c;
}

/// Bounds on the blind stretch need a stretch: a cover: or a kidnap:.
void check_blind_bounds(const Scenario& s, const ReadContext& ctx) {
  if (!s.expect.any_blind_bound() || s.cover || s.kidnap) return;
  const Expectations& e = s.expect;
  const char* key = e.blind_poses_all             ? "blind_poses_all"
                    : e.blind_after_error_m_max   ? "blind_after_error_m_max"
                    : e.blind_after_error_deg_max ? "blind_after_error_deg_max"
                                                  : "blind_no_global_relocalisation";
  throw ConfigError(ctx.origins->where(std::string("expect.") + key, ctx.file), std::string("expect.") + key,
                    "a scenario with a cover: or kidnap: section (the bound is on its covered frames)",
                    "no covered frames");
}

/// Checks between fields: the route against the arrays it names.
void check_route(const Scenario& s, const ReadContext& ctx) {
  const Route& rt = s.route;
  const auto at = [&](const char* key) { return ctx.origins->where(std::string("route.") + key, ctx.file); };
  if (rt.pattern == RoutePattern::kWaypoints && rt.waypoints_m.size() < 2)
    throw ConfigError(at("pattern"), "route.waypoints_m", "at least 2 points when route.pattern is waypoints");
  if (rt.pattern != RoutePattern::kWaypoints) {
    if (s.pv_arrays.empty())
      throw ConfigError(at("pattern"), "route.pattern", "a waypoints route when the scenario has no pv_arrays",
                        to_string(rt.pattern));
    if (rt.array >= static_cast<int>(s.pv_arrays.size()))
      throw ConfigError(at("array"), "route.array", "an index below " + std::to_string(s.pv_arrays.size()),
                        std::to_string(rt.array));
    const PvArray& a = s.pv_arrays[static_cast<std::size_t>(rt.array)];
    if (rt.pattern == RoutePattern::kAlongRow && rt.aisle > a.rows)
      throw ConfigError(at("aisle"), "route.aisle", "an aisle in [0, " + std::to_string(a.rows) + "]",
                        std::to_string(rt.aisle));
    if (rt.pattern == RoutePattern::kLawnmower && rt.first_aisle + rt.aisles > a.rows + 1)
      throw ConfigError(at("aisles"), "route.aisles",
                        "at most rows + 1 - first_aisle = " + std::to_string(a.rows + 1 - rt.first_aisle),
                        std::to_string(rt.aisles));
    const double first_aisle_m = row_length_m(a) + 2 * rt.margin_m;
    if (rt.pattern == RoutePattern::kLawnmower && rt.return_to_start && rt.return_overlap_m > first_aisle_m)
      throw ConfigError(at("return_overlap_m"), "route.return_overlap_m",
                        "at most the first aisle's length, " + format_number("%.2f m", first_aisle_m),
                        format_exact(rt.return_overlap_m));
  }
  if (rt.start_m > 0) {
    // A start part-way must leave a route to drive.
    const double length = polyline_length(route_polyline(s));
    if (!(rt.start_m < length - 1.0))
      throw ConfigError(
          at("start_m"), "route.start_m",
          "a distance at least 1 m before the route's end (" + format_number("%.2f m", length) + " long)",
          format_exact(rt.start_m));
  }
}

/// ground.relief: roughness and slope; under a repeated soil, checked
/// against the samples its one height field may have (a varied soil's
/// relief is drawn tile by tile).
void read_relief(MapReader& q, Ground& g) {
  Relief rl;
  rl.amplitude_cm = q.number("amplitude_cm", rl.amplitude_cm, 0, 20);
  rl.scale_m = q.number("scale_m", rl.scale_m, 0.2, 50);
  rl.slope_percent = q.number("slope_percent", rl.slope_percent, 0, 30);
  rl.slope_azimuth_deg = q.number("slope_azimuth_deg", rl.slope_azimuth_deg, -360, 360);
  rl.cell_m = q.number("cell_m", rl.cell_m, 0.05, 2);
  if (rl.cell_m > rl.scale_m / 2)
    q.fail(q.full("cell_m"), YAML::Node(),
           "a cell of at most half of scale_m (" + format_exact(rl.scale_m / 2) + " m), to draw the bumps",
           format_exact(rl.cell_m));
  const Eigen::Vector2i n = relief_samples(g.size_m, rl.cell_m);
  if (g.tiling == GroundTiling::kRepeat && static_cast<long long>(n.x()) * n.y() > kMaxReliefSamples)
    q.fail(q.full("cell_m"), YAML::Node(),
           "a cell that samples ground.size_m in at most " + std::to_string(kMaxReliefSamples) + " points",
           format_exact(rl.cell_m) + " m (" + std::to_string(n.x()) + " x " + std::to_string(n.y()) + " points)");
  g.relief = rl;
}

void read_ground(MapReader& r, Ground& g) {
  g.type = r.choice<GroundType>("type", g.type, {{"soil", GroundType::kSoil}, {"gravel", GroundType::kGravel}});
  g.size_m = r.vec2("size_m", g.size_m, 5, 2000);
  // A relief takes one repeated image: without a tiling given, that is its default.
  const GroundTiling fallback = r.has("relief") ? GroundTiling::kRepeat : g.tiling;
  g.tiling = r.choice<GroundTiling>("tiling", fallback,
                                    {{"repeat", GroundTiling::kRepeat}, {"varied", GroundTiling::kVaried}});
  g.soil_images = r.integer("soil_images", g.soil_images, 1, 1000);
  if (g.soil_images > 0 && g.tiling != GroundTiling::kVaried)
    r.fail(r.full("soil_images"), r.child("soil_images"), "soil_images with tiling: varied only");
  g.unique_within_m = r.number("unique_within_m", g.unique_within_m, 0, 20);
  if (r.has("unique_within_m") && g.soil_images == 0)
    r.fail(r.full("unique_within_m"), r.child("unique_within_m"), "unique_within_m with soil_images only",
           format_exact(g.unique_within_m));
  with_map(r, "relief", [&](MapReader& q) { read_relief(q, g); });
  if (r.has("friction")) g.friction = r.number("friction", 0.0, 0.05, 2);
  g.softness = r.number("softness", g.softness, 0, 1);
}

/// A height field ends at its edge, and a robot driven past it falls:
/// every route point must lie kRouteGroundMarginM inside ground.size_m.
void check_route_on_relief(const Scenario& s, const std::vector<Eigen::Vector2d>& route,
                           const ReadContext& ctx) {
  const Eigen::Vector2d half = 0.5 * s.ground.size_m - Eigen::Vector2d::Constant(kRouteGroundMarginM);
  for (const Eigen::Vector2d& p : route) {
    if (std::abs(p.x()) <= half.x() && std::abs(p.y()) <= half.y()) continue;
    throw ConfigError(ctx.origins->where("ground.size_m", ctx.file), "ground.size_m",
                      "a relief that holds the route with " + format_number("%.1f m", kRouteGroundMarginM) +
                          " to spare on every side (the robot falls off a height field's edge): at least [" +
                          format_number("%.1f", 2 * (std::abs(p.x()) + kRouteGroundMarginM)) + ", " +
                          format_number("%.1f", 2 * (std::abs(p.y()) + kRouteGroundMarginM)) + "]",
                      "[" + format_exact(s.ground.size_m.x()) + ", " + format_exact(s.ground.size_m.y()) +
                          "], and the route reaches (x, y) = (" + format_number("%.2f", p.x()) + ", " +
                          format_number("%.2f", p.y()) + ") m");
  }
}

/// A relief the robot cannot drive: the first route point where a grade
/// exceeds kMaxRouteGrade, named at the key that makes it (the slope when
/// the plane alone is too steep there, else the roughness).
void check_ground_relief(const Scenario& s, const ReadContext& ctx) {
  if (!s.ground.relief) return;
  const std::vector<Eigen::Vector2d> route = route_polyline(s);
  check_route_on_relief(s, route, ctx);
  const GroundRelief ground(s);
  const auto fault = find_route_grade_fault(ground, route, kRobotWheelBaseM, s.robot.track_m);
  if (!fault) return;
  Relief plane = *s.ground.relief;
  plane.amplitude_cm = 0;
  const bool slope = find_route_grade_fault(GroundRelief(plane, s.ground.size_m, 0), route, kRobotWheelBaseM,
                                            s.robot.track_m).has_value();
  const std::string key = std::string("ground.relief.") + (slope ? "slope_percent" : "amplitude_cm");
  throw ConfigError(ctx.origins->where(key, ctx.file), key,
                    "a relief the robot can drive: grades of at most " + format_number("%.0f", 100 * kMaxRouteGrade) +
                        " % along its route, over its wheel base (" + format_number("%.2f", kRobotWheelBaseM) +
                        " m) and across its track (" + format_number("%.2f", s.robot.track_m) + " m)",
                    format_number("%.1f", 100 * std::abs(fault->grade)) + " % " +
                        (fault->across ? "across" : "along") + " the route at (x, y) = (" +
                        format_number("%.2f", fault->at_m.x()) + ", " + format_number("%.2f", fault->at_m.y()) +
                        ") m");
}

}  // namespace pvb::scenes::detail
