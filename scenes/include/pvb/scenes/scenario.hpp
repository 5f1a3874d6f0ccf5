#pragma once
// A scenario: everything needed to simulate one run of the robot in a
// photovoltaic station.  Loaded from YAML (see scenes/SCHEMA.md) and
// validated on load: unknown keys, wrong types and out-of-range values are
// ConfigErrors naming the file, the line, the key and what was expected.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/scenes/motion_sensor_specs.hpp"
#include "pvb/scenes/plant_summary.hpp"

namespace pvb::scenes {

enum class GroundType { kSoil, kGravel };
/// How the ground's soil image covers it: one image repeated every 3 m, or
/// near the route every 3 m tile an image of its own.
enum class GroundTiling { kRepeat, kVaried };
enum class PanelOrientation { kPortrait, kLandscape };
enum class RoutePattern { kWaypoints, kAlongRow, kLawnmower, kLoop, kRoads };
enum class DepthNoiseModel { kNone, kKinect };
/// The depth camera: a structured-light Kinect v1 (the depth_noise model)
/// or an active stereo RealSense D435 (ActiveStereo).
enum class CameraKind { kKinect, kD435 };
enum class OnLoss { kWait, kAbort };
enum class WallFinish { kBrick, kPlaster };
/// How an array's panels are held: fixed tilted tables, or rows of modules
/// on a horizontal torque tube that turns with the sun.
enum class Mount { kFixed, kSingleAxis };

/// A single-axis tracker row's mechanics and its angle on the day.  The
/// torque tube runs along the row (the array's u axis, azimuth_deg); its
/// rotation is right-handed about +u, 0 with the panels flat.
struct TrackerMount {
  double max_angle_deg = 55.0;  ///< the rotation stays in [-max, max] (45-60 are usual)
  bool backtrack = true;        ///< turn back from the sun so that rows do not shade each other
  /// A fixed angle (stow, or parked for cleaning); unset: true tracking
  /// with backtracking from the day's sun (pvlib's singleaxis).
  std::optional<double> fixed_rotation_deg;
};

/// Uneven ground (`ground.relief`): roughness over an overall slope, from
/// the station's seed (pvb/scenes/ground_relief.hpp says how it is made).
struct Relief {
  double amplitude_cm = 2.0;       ///< standard deviation of the roughness
  double scale_m = 1.0;            ///< its correlation length
  double slope_percent = 0.0;      ///< overall grade, rise over run x 100
  double slope_azimuth_deg = 0.0;  ///< direction the ground rises, CCW from world x
  double cell_m = 0.25;            ///< grid spacing (at most)
};

struct Ground {
  GroundType type = GroundType::kSoil;
  Eigen::Vector2d size_m{60.0, 60.0};  ///< extent along x and y, centred at origin
  /// Varied: every 3 m of soil near the route an image of its own (under a
  /// relief each such tile is a height field of its own).  Repeat: one
  /// image over the whole ground, the default under a relief.
  GroundTiling tiling = GroundTiling::kVaried;
  /// Varied tiling: 0 gives every tile an image of its own (at most 200
  /// tiles); N > 0 draws N images, and each tile takes one of them with a
  /// quarter turn, both from the station's seed and the tile's place
  /// (memory bounded by N, not by the route).
  int soil_images = 0;
  /// With soil_images: within this distance of the camera every tile shows
  /// an image of its own instead, drawn as the camera nears it, so no two
  /// places of the route look alike up close (0: the shared images only).
  double unique_within_m = 12.0;
  std::optional<Relief> relief;  ///< none: the flat plane z = 0
  /// The tiling the ground is drawn with.
  GroundTiling drawn_tiling() const { return tiling; }
  /// Sliding friction of the soil against the tyres (the day's: wet soil
  /// slips).  None: MuJoCo's default combination (the larger of soil 1 and
  /// tyre 1.2).  Given: the ground's friction governs every contact with it.
  std::optional<double> friction;
  /// How soft the soil is under the tyres (the day's: wet earth gives):
  /// 0 is MuJoCo's default contact, 1 a soft contact (solref 0.1 s, solimp
  /// 0.5 0.7 0.01) in which the tyres sink and creep under traction.
  double softness = 0;
  /// Whether the ground's contact parameters govern its contacts.
  bool governs_contact() const { return friction.has_value() || softness > 0; }
};

/// Trackers: the panels sit this far above the torque tube's axis, along
/// their normal (the tube and the purlins between them).
inline constexpr double kTrackerPanelAboveAxisM = 0.10;

/// Rows of PV tables.  Array frame: u along the rows (azimuth_deg,
/// counter-clockwise from world x), v across them; rows stack towards +v.
/// Fixed mount: tilted tables whose panels face -v (up by tilt_deg).
/// Single-axis mount: each row's tables turn on a torque tube along u, the
/// row's middle (v = row pitch x row + table depth / 2), by rotation_deg.
struct PvArray {
  Eigen::Vector2d origin_m{0.0, 0.0};  ///< front-left corner of the first row
  double azimuth_deg = 0.0;
  int rows = 2;
  int tables_per_row = 3;
  int panels_per_table = 8;  ///< panels side by side along the row, per line
  int panel_lines = 2;       ///< lines of panels up the slope
  PanelOrientation orientation = PanelOrientation::kPortrait;
  int cells = 72;            ///< 60, 72 or 144 (half-cut)
  double tilt_deg = 25.0;
  double row_pitch_m = 6.0;  ///< distance between the front edges of two rows
  double table_gap_m = 1.0;
  double clearance_m = 0.6;  ///< height of the lowest panel edge
  bool posts = true;
  bool rails = true;
  double dirt = 0.2;         ///< 0 clean .. 1 very dusty
  /// The modules' front glass: diffuse (a matte surface with a highlight,
  /// as the bench always drew it) or specular (the sky mirrored with
  /// Fresnel's angle dependence, the sun's glint, and what the mirror does
  /// to depth; docs/sensors.md, "Glass").
  bool specular_glass = false;
  /// Every table of the array gets the same panels (the same dust variants
  /// in the same places), so its tables and rows look alike.  False: each
  /// panel's variant is drawn on its own.
  bool identical_tables = false;
  /// Each table's panels drawn as one slab, its module texture repeated
  /// once per module (a plant's arrays: a few geoms a table, not one a
  /// module).  False: one geom per module, 2 cm apart.
  bool panel_slabs = false;
  /// Soiling that varies from row to row (slabs only): every table of a row
  /// takes the row's dust variant, drawn from the station's seed, and the
  /// variants spread over dirt x [1 - s, 1 + s].  0: each table draws its
  /// own variant from the day's seed, over dirt x [0.55, 1].
  double row_soiling = 0.0;
  /// Modules shown broken (slabs only): shattered glass over this many
  /// modules of the array, where the station's seed puts them.
  int broken_modules = 0;
  /// Modules gone (slabs only): this many modules of the array, none of
  /// them broken, where the station's seed puts them.  A table that lost
  /// one is drawn a module at a time, its backsheet too, so the rails and
  /// the ground show through the gap.
  int missing_modules = 0;
  Mount mount = Mount::kFixed;
  TrackerMount tracker;  ///< mount single_axis only
  /// The tracker's rotation on the day (degrees; 0 for a fixed mount),
  /// resolved by the loader from the sun or tracker.rotation_deg.
  double rotation_deg = 0.0;
  /// The true-tracking angle before backtracking and clipping (trackers
  /// following the sun only; equal to rotation_deg otherwise).
  double ideal_rotation_deg = 0.0;

  // Derived panel size (m) from cells and orientation.
  double panel_width_m() const;   ///< along the row
  double panel_height_m() const;  ///< up the slope
  double table_length_m() const;  ///< along the row
  double table_depth_m() const;   ///< slope length of a table
  /// Trackers: module width across the tube over the row pitch.
  double ground_coverage_ratio() const { return table_depth_m() / row_pitch_m; }
  /// Trackers: height of the torque tube's axis, so that the lowest panel
  /// edge is clearance_m above the ground at the largest rotation.
  double axis_height_m() const;
};

struct Wall {
  Eigen::Vector2d start_m{0.0, 0.0};
  Eigen::Vector2d end_m{10.0, 0.0};
  double height_m = 2.0;
  double thickness_m = 0.24;
  /// Brick (grey bricks of highly similar look) or plaster (one flat,
  /// untextured colour, e.g. the side of an inverter station).
  WallFinish finish = WallFinish::kBrick;
};

struct Vegetation {
  int shrubs = 0;
  Eigen::Vector2d shrub_size_m{0.3, 0.9};  ///< min, max diameter
  int trees = 0;
  Eigen::Vector2d tree_height_m{2.0, 4.0};
  Eigen::Vector4d area_m{-10, -10, 10, 10};  ///< xmin, ymin, xmax, ymax
  double keep_out_m = 1.0;                   ///< clearance from route, walls and arrays
  /// How much the plants have grown (or been cut back) on the day: their
  /// sizes scale by this, where they stand does not.
  double growth = 1.0;
};

struct Light {
  double sun_azimuth_deg = 135.0;   ///< direction the sun is in, CCW from world x
  double sun_elevation_deg = 45.0;
  double intensity = 0.8;           ///< diffuse of the sun light, 0..1
  double ambient = 0.35;            ///< ambient light, 0..1
  bool shadows = true;
  /// Shadow map side in texels; 0 picks the smallest power of two from 1024
  /// that keeps texels at most 20 mm over the area the map covers.
  int shadow_map_px = 0;
  /// false (default): the shadow map is fixed in the world and covers the
  /// route plus 9 m around it, so shadows are static.  true: MuJoCo's
  /// tracking sun, a map of 18 m around the robot that moves with it;
  /// MuJoCo 2.2.2 draws that map 2 texels smaller than it samples it, so
  /// every shadow then creeps along with the robot by about 0.2 % of the
  /// distance driven (docs/scenarios.md, "Static shadows").
  bool shadow_follows_robot = false;
  /// Quads along each edge of a box face (MuJoCo vis.quality.numquads);
  /// only per-vertex lighting uses them.  1 renders faster (docs/run.md).
  int box_quads = 1;
};

/// Where the station is and when the day's run happens: the sun's position
/// follows from them (NOAA's solar position algorithm).
struct Site {
  double latitude_deg = 0.0;   ///< north positive
  double longitude_deg = 0.0;  ///< east positive
  std::string date;            ///< YYYY-MM-DD, local
  std::string time;            ///< HH:MM[:SS], local
  double utc_offset_h = 0.0;   ///< local = UTC + offset (daylight saving included)
  double pressure_hpa = 1010.0;
  double temperature_c = 10.0;
};

/// The sun of the run, as resolved by the loader (for reports).
struct SunPosition {
  enum class Source { kDefault, kLight, kSite };
  Source source = Source::kDefault;  ///< light.* keys (or their defaults), or the site and time
  double solar_azimuth_deg = 0.0;    ///< clockwise from north (world +y), [0, 360)
  double elevation_deg = 0.0;        ///< apparent, above the horizon
};

struct Route {
  RoutePattern pattern = RoutePattern::kWaypoints;
  std::vector<Eigen::Vector2d> waypoints_m;  ///< for kWaypoints
  int array = 0;                             ///< pattern routes: which array
  int aisle = 0;                             ///< along_row: aisle in front of this row
  int aisles = 2;                            ///< lawnmower: number of aisles driven
  int laps = 1;                              ///< loop: times around the array
  /// roads: 0 for the perimeter road, k for the roads around the plant's
  /// block k (from 1, as its row signs count).
  int block = 0;
  /// lawnmower: after the last aisle, drive back to the start beyond the row
  /// ends and re-drive the first aisle's first return_overlap_m metres in
  /// the direction of the start.
  bool return_to_start = false;
  double return_overlap_m = 4.0;             ///< lawnmower with return_to_start
  int first_aisle = 0;                       ///< lawnmower: the first aisle driven
  /// lawnmower in a plant: start at the plant's dock (its aisle must be the
  /// first driven), drive the aisles, and come back to the same place.
  bool from_dock = false;
  double offset_m = 1.5;                     ///< distance from the table edges
  double margin_m = 2.0;                     ///< run-out beyond the row ends
  double speed_mps = 0.5;
  double lookahead_m = 0.6;                  ///< pure pursuit lookahead
  /// The robot starts this far along the route and drives the rest of it
  /// (a session that begins part-way; the route itself is unchanged).
  double start_m = 0.0;
  OnLoss on_loss = OnLoss::kWait;            ///< closed loop: what to do when tracking is lost
};

/// Sunlight on a structured-light camera's projected pattern
/// (docs/sensors.md, "Sunlight"): a depth pixel survives while the pattern's
/// irradiance on the surface, P cos(theta_p) / (Omega r^2), is at least
/// `min_contrast` times the ambient near-infrared in the camera's band, the
/// sun's beam on the surface (where no geom shadows it) plus the sky's.
struct Sunlight {
  bool on = true;  ///< off: depth as indoors, whatever the sun
  double projector_power_w = 0.06;         ///< Kinect v1's 830 nm laser at its output (OpenKinect)
  double projector_solid_angle_sr = 0.70;  ///< the pattern's 58 x 45 degree field
  double filter_width_nm = 10.0;           ///< the infrared camera's band-pass (not published)
  double sun_w_m2_nm = 0.85;               ///< direct normal at 830 nm, ASTM G173 (air mass 1.5)
  double sky_share = 0.10;                 ///< the sky's irradiance on any surface, share of the beam's
  /// Pattern over ambient below which the pattern is lost: a shaded surface
  /// facing the camera keeps depth to the Kinect's rated 4.0 m at air mass 1.5.
  double min_contrast = 0.0063;
};

struct DepthNoise {
  DepthNoiseModel model = DepthNoiseModel::kKinect;
  Sunlight sunlight;                 ///< applies to the kinect model
  double baseline_m = 0.075;         ///< IR projector-camera baseline
  double disparity_step_px = 0.125;  ///< disparity quantisation (1/8 px)
  double lateral_sigma_px = 0.5;     ///< pixel jitter of the depth sampling
  double axial_scale = 1.0;          ///< multiplies sigma_z = 0.0012 + 0.0019 (z - 0.4)^2
  double max_incidence_deg = 80.0;   ///< invalid beyond this view/normal angle
};

/// An active stereo camera (RealSense D435): two infrared imagers that see
/// the scene's light and a projected dot pattern, depth from semi-global
/// matching (docs/sensors.md, "Active stereo").  Figures from Intel's D400
/// documents and the FRAMOS D435e manual unless marked otherwise.
struct ActiveStereo {
  int ir_width = 848;               ///< the D435's best depth resolution
  int ir_height = 480;
  double ir_fx = 446.7;             ///< 87 degrees across 848 pixels
  double baseline_m = 0.050;        ///< between the two imagers
  double colour_offset_m = 0.015;   ///< from the left imager to the colour camera, along x
  double projector_offset_m = 0.025;  ///< from the left imager to the projector, along x
  double projector_power_w = 0.36;  ///< average optical power, 850 nm
  double projector_hfov_deg = 86.0;
  double projector_vfov_deg = 57.0;
  int dots = 5000;                  ///< the pattern's spots
  std::uint64_t pattern_seed = 435; ///< where the spots lie (a property of the device)
  /// The sun's beam at air mass 1.5 in the imagers' band (no infrared-cut
  /// filter: about 400-1000 nm of ASTM G173's direct spectrum).
  double band_sun_w_m2 = 600.0;
  double sky_share = 0.12;          ///< the sky's irradiance on any surface, share of the beam's
  double min_ambient_w_m2 = 1.0;    ///< the ambient floor without sun (dusk, indoors)
  int disparities = 128;            ///< the D4's 126, rounded up to OpenCV's multiple of 16
  int block_px = 7;                 ///< the matcher's window
  int uniqueness_pct = 10;          ///< the matcher's uniqueness ratio
  double ir_noise_sigma = 2.0;      ///< 8-bit levels, after exposure
  /// The left imager's intrinsics (square pixels, centred principal point).
  double ir_cx() const { return 0.5 * ir_width - 0.5; }
  double ir_cy() const { return 0.5 * ir_height - 0.5; }
  double ir_fovy_deg() const;
};

struct RgbNoise {
  double sigma = 1.5;     ///< additive Gaussian noise, 8-bit levels
  double exposure = 1.0;  ///< gain applied before noise
  double glare = 0.0;     ///< strength of sun glare when the sun is in view, 0..1
  /// Automatic exposure, as a Kinect's colour camera has it: each frame's
  /// gain brings the mean grey of the image's central region to middle
  /// grey (within [1/4, 8] times `exposure`), and the noise grows with it.
  /// false: the fixed `exposure`.
  bool auto_exposure = false;
};

struct Camera {
  int width = 640;
  int height = 480;
  double fx = 525.0;  ///< MuJoCo 2.2.2 renders square pixels: fx must equal fy
  double fy = 525.0;
  double fps = 30.0;
  double mount_height_m = 0.8;
  double mount_forward_m = 0.15;
  double pitch_deg = -12.0;  ///< negative looks down
  double yaw_deg = 0.0;      ///< relative to the robot's heading, positive left
  Eigen::Vector2d depth_range_m{0.5, 4.5};
  CameraKind model = CameraKind::kKinect;
  DepthNoise depth_noise;  ///< the kinect model's depth
  ActiveStereo stereo;     ///< the d435 model's depth
  RgbNoise rgb;
  // Principal point of MuJoCo's symmetric frustum, pixel-centre convention.
  double cx() const { return 0.5 * width - 0.5; }
  double cy() const { return 0.5 * height - 0.5; }
  /// MuJoCo's vertical field of view giving focal length fy: the image spans
  /// height pixels, so tan(fovy / 2) = (height / 2) / fy.
  double fovy_deg() const;
  /// The depth sensor's baseline: the Kinect's projector to camera, the
  /// D435's imager to imager.
  double depth_baseline_m() const { return model == CameraKind::kD435 ? stereo.baseline_m : depth_noise.baseline_m; }
  /// The D435's own colour camera and depth range: 640 x 480 at fx 615,
  /// [0.2, 6] m (the d435 model's defaults, before the file's keys).
  void use_d435_colour_camera() {
    width = 640;
    height = 480;
    fx = fy = 615.0;
    depth_range_m = {0.2, 6.0};
  }
};

/// The robot's caster is this far behind the wheels' axle: its wheel base.
inline constexpr double kRobotWheelBaseM = 0.36;
/// How far inside a relief's edge every route point must lie: the robot's
/// half length (0.4 m), with room for the path follower to swing wide at a corner.
inline constexpr double kRouteGroundMarginM = 1.0;

/// The robot as built (the simulated one).  The description a SLAM core or
/// an odometry gets (robot.yaml) has nominal values that differ from these
/// by a calibration error drawn from the station seed, uniform within
/// +-radius_error and +-track_error (relative), as a robot measured with a
/// tape differs from its drawing.
struct Robot {
  double wheel_radius_m = 0.1;
  double track_m = 0.42;  ///< distance between the wheel contact points
  double max_wheel_speed_radps = 12.0;
  /// Largest change of a wheel's commanded speed, rad/s^2 (unset: none,
  /// a command takes effect at once and a start or stop rocks the robot).
  std::optional<double> max_wheel_accel_radps2;
  double radius_error = 0.01;  ///< largest relative error of the nominal wheel radius
  double track_error = 0.02;   ///< largest relative error of the nominal track
  /// As built, the right wheel's radius over the left's, less one; the
  /// wheels are wheel_radius_m * (1 -+ radius_difference / 2).  The
  /// description gives them the same radius, as a tape would.
  double radius_difference = 0.0;
  double left_radius_m() const { return wheel_radius_m * (1 - 0.5 * radius_difference); }
  double right_radius_m() const { return wheel_radius_m * (1 + 0.5 * radius_difference); }
};

/// SLAM settings the scenario asks for (the `slam:` section).  They go into
/// the ORB-SLAM2 settings file written with every recording and run
/// (camera.yaml), so a run and a replay of the recording use the same ones.
struct SlamTuning {
  int orb_features = 1000;  ///< ORBextractor.nFeatures
  /// KeyFrame.minTrackedClose (pvbench's own key; unset: the SLAM default)
  std::optional<int> keyframe_min_tracked_close;
  /// KeyFrame.refOverlap (pvbench's own key; unset: ORB-SLAM2's 75 % rule)
  std::optional<double> keyframe_ref_overlap;
  /// System.Sensors (pvbench's own key; unset: camera): the sensors the
  /// SLAM core fuses.
  std::optional<sensor::SensorSetup> sensors;
};

/// What a seed sweep of this scenario must show (`expect.sweep:`), judged by
/// `pvbench sweep --compare --check` (harness/suite).  A comparison between
/// PE-SLAM and the baseline is a claim about a distribution, so it is judged
/// over seeds, never on one run (docs/scenarios.md).
struct SweepExpectations {
  /// PE-SLAM is not significantly worse than the baseline: the upper end of
  /// the paired 95 % interval of (PE − baseline) ATE RMSE is at most
  /// max(0.5 mm, 10 % of the baseline's mean ATE RMSE).
  bool pe_not_significantly_worse = false;
  int min_seeds = 10;  ///< seeds with both ATEs the verdict needs
  bool any() const { return pe_not_significantly_worse; }
};

/// What a run of this scenario must achieve (the `expect:` section).  The
/// checker in harness/suite compares a run's metrics.json against it.  A
/// bound that is not set (has_*) is not checked.
struct Expectations {
  // Unset bounds are not checked.
  std::optional<double> ate_rmse_m_max;        ///< ATE RMSE of the primary run, metres
  std::optional<double> rpe_trans_rmse_m_max;  ///< RPE translation RMSE of the primary run, metres
  std::optional<int> lost_frames_max;          ///< frames in the Lost state
  /// Keyframes in the final map (after culling): a map that keeps growing
  /// over ground it has mapped fails it.
  std::optional<int> keyframes_max;
  /// ATE RMSE of the refined trajectory (every frame re-anchored on its
  /// keyframe's final pose, after local BA and loop closing), metres.
  std::optional<double> refined_ate_rmse_m_max;
  /// Place recognition, judged against ground truth: at most this many
  /// false loops, and at most this many false relocalisations.
  std::optional<int> false_loops_max;
  /// Every loss must end in a true relocalisation within this many frames
  /// of the camera's return (the loss's first frame, or the end of a
  /// scenario's camera cover, whichever is later).
  std::optional<int> relocalised_within_frames;
  /// At least this many true loops (found by the place recognition).
  std::optional<int> loops_min;
  /// The corrected dense map against the true surface (docs/map_accuracy.md):
  /// median distance of its points to the surface, metres, at most this;
  /// and at least this share (0-1) of the surface within 5 cm of the map.
  std::optional<double> map_accuracy_m_max;
  std::optional<double> map_completeness_min;
  /// The blind stretch (a `cover:` or a kidnap's covered frames): every
  /// covered frame has a pose; the first frame after the cover, relative to
  /// the last pose before it, within these bounds of the truth; and that
  /// frame tracked without a global relocalisation (none during the cover
  /// either).
  bool blind_poses_all = false;
  std::optional<double> blind_after_error_m_max;
  std::optional<double> blind_after_error_deg_max;
  bool blind_no_global_relocalisation = false;
  bool tracking_loss_expected = false;         ///< the run must report a loss with a reason
  int ci_frames = 0;                           ///< frames of the fast CI run; 0 = not in the fast subset
  SweepExpectations sweep;                     ///< judged over a seed sweep only
  /// True when a bound on a single run is set.
  bool any_run_bound() const {
    return ate_rmse_m_max || rpe_trans_rmse_m_max || lost_frames_max || keyframes_max ||
           tracking_loss_expected || refined_ate_rmse_m_max || false_loops_max || relocalised_within_frames ||
           loops_min || map_accuracy_m_max || map_completeness_min || any_blind_bound();
  }
  /// True when a bound on the blind stretch is set.
  bool any_blind_bound() const {
    return blind_poses_all || blind_after_error_m_max || blind_after_error_deg_max ||
           blind_no_global_relocalisation;
  }
  /// True when any bound or flag is set.
  bool any() const { return any_run_bound() || sweep.any(); }
};

/// The camera is covered for a while and meanwhile the robot is carried to
/// where it was earlier (the `kidnap:` section).  While covered, the sensor
/// delivers black colour (plus its noise) and no depth; in the middle of the
/// covered frames the simulator puts the robot back into its exact state at
/// to_route_s (pose, velocities and the route follower's progress), and it
/// drives the route on from there.
struct Kidnap {
  double at_s = 0;        ///< the lens is covered from this time
  double covered_s = 2;   ///< for this long
  double to_route_s = 0;  ///< the robot is carried to its state at this earlier time
};

/// The camera is covered for a while, as in a kidnap, but the robot drives
/// on along its route (the `cover:` section): its IMU and wheel encoders
/// read as usual.
struct Cover {
  double at_s = 0;       ///< the lens is covered from this time
  double covered_s = 2;  ///< for this long
};

/// The frames a covered lens spans (frame i is at i / fps).
struct CoverFrames {
  int begin = 0;  ///< first covered frame: the first at or after at_s
  int end = 0;    ///< first frame after the cover: the first at or after at_s + covered_s
  bool covered(std::int64_t frame) const { return frame >= begin && frame < end; }
};

/// A kidnap in frame indices (frame i is at i / fps).
struct KidnapFrames {
  int cover_begin = 0;  ///< first covered frame: the first at or after at_s
  int cover_end = 0;    ///< first frame after the cover: the first at or after at_s + covered_s
  int teleport = 0;     ///< the first frame in the new place: the middle of the covered frames
  int target = 0;       ///< the frame whose state the robot is carried to: at or just before to_route_s
  bool covered(std::int64_t frame) const { return frame >= cover_begin && frame < cover_end; }
};

struct Scenario {
  std::string source_file;  ///< where it was loaded from ("" if built in code)
  /// The files it derives from (base:), nearest first; empty for a file
  /// that stands alone.
  std::vector<std::string> base_files;
  std::string name = "unnamed";
  std::string description;
  /// The day's seed: dust on the panels, sensor noise, PE-match's particles
  /// (and, without station_seed, the station too).
  std::uint64_t seed = 0;
  /// The station's seed: what stays from day to day (textures of soil,
  /// bricks, cells and plants, where the plants stand).  Unset: `seed`.
  std::optional<std::uint64_t> station_seed;
  std::uint64_t station_seed_or_seed() const { return station_seed.value_or(seed); }
  double duration_s = 20.0;
  Ground ground;
  std::vector<PvArray> pv_arrays;
  std::vector<Wall> walls;
  std::optional<PlantSummary> plant;  ///< none unless the file has a plant: section
  Vegetation vegetation;
  Light light;
  std::optional<Site> site;  ///< none unless the file has a site: section
  SunPosition sun;           ///< resolved from site: or light:
  Route route;
  Robot robot;
  Camera camera;
  Physics physics;
  Imu imu;
  Wheels wheels;
  SlamTuning slam;
  std::optional<Kidnap> kidnap;  ///< none unless the file has a kidnap: section
  std::optional<Cover> cover;    ///< none unless the file has a cover: section (never with a kidnap)
  Expectations expect;
};

/// The sun's diffuse light (light.intensity) for a sun at this apparent
/// elevation, when the site gives the sun and the file does not set it: the
/// default 0.8 at 45 degrees, scaled by the clear-sky beam that reaches the
/// ground, 0.7^(AM^0.678) (Meinel and Meinel 1976) with the air mass of
/// Kasten and Young (1989); in [0.05, 1].
double sun_intensity_for(double elevation_deg);
/// The share of the sun's beam that reaches the ground through a clear sky,
/// 0.7^(AM^0.678) (Meinel and Meinel 1976; Kasten and Young's air mass); 0
/// for a sun at or below the horizon.
double clear_sky_beam_share(double elevation_deg);
/// The beam at this elevation relative to the beam of ASTM G173's
/// reference sun (air mass 1.5, 41.81 degrees up): what multiplies a
/// spectral irradiance read off G173.
double beam_relative_to_air_mass_15(double elevation_deg);
/// The sky's light (light.ambient) likewise: the default 0.35 at 45
/// degrees, 0.45 + 0.55 sin(elevation) / sin(45) of it; in [0.1, 0.6].
double sky_ambient_for(double elevation_deg);

/// Loads and validates a scenario file.  Throws ConfigError or IoError.
Scenario load_scenario(const std::string& path);
/// Same, from YAML text; `origin` names the source in error messages.
Scenario parse_scenario(const std::string& yaml_text, const std::string& origin);

/// Frames the scenario yields: floor(duration_s * fps) + 1, capped by max_frames if > 0.
int frame_count(const Scenario& s, int max_frames = 0);

/// Physics steps a camera frame: physics.rate_hz / fps, or, unset, the
/// fewest steps of at most 2 ms each that fill the camera period.
int physics_substeps(const Scenario& s);
/// Physics steps a second: fps x physics_substeps.
double physics_rate_hz(const Scenario& s);
/// The IMU's and the wheel encoders' sample rates (body.hpp says how an
/// unset rate is chosen).
double imu_rate_hz(const Scenario& s);
double wheel_rate_hz(const Scenario& s);

/// The kidnap's frames at the scenario's frame rate.
KidnapFrames kidnap_frames(const Kidnap& k, double fps);
/// The cover's frames at the scenario's frame rate.
CoverFrames cover_frames(const Cover& c, double fps);
/// The frames the scenario's camera is covered: its cover's, or its
/// kidnap's; nullopt with neither.
std::optional<CoverFrames> camera_cover_frames(const Scenario& s);

const char* to_string(RoutePattern p);

}  // namespace pvb::scenes
