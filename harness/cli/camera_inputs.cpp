// pvbench camera's inputs and settings (camera_inputs.hpp).
#include "camera_inputs.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "io_plan.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/dataset/fakenect_dump.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/openni/oni_file.hpp"
#include "pvb/openni/record_target.hpp"
#include "pvb/openni/sim_uri.hpp"
#include "pvb/run/motion_truth.hpp"
#include "pvb/run/output_names.hpp"
#include "pvb/run/run.hpp"
#include "sensor_options.hpp"
#include "stop_signals.hpp"

namespace pvb::cli::camera {

/// What a source gives SLAM beside images, against the sensor setup: a
/// sim:// device its robot's IMU and encoders (the ground-truth simulator's
/// readings), a Kinect v1 (freenect://) its accelerometer, an .oni
/// recording or another OpenNI2 camera nothing.  A setup that needs more is
/// refused (`file`, `key`: where it was asked for) before any device opens.
void refuse_unfed_setup(const CameraArgs& a, sensor::SensorSetup setup, const std::string& file,
                        const std::string& key) {
  if (setup == sensor::SensorSetup::kCamera || (a.oni.empty() && openni::is_sim_uri(a.uri))) return;
  const std::string got = sensor::to_string(setup);
  if (is_freenect_uri(a)) {
    if (setup == sensor::SensorSetup::kCameraAccel) return;
    throw ConfigError(file, key,
                      "camera or camera+accel for a Kinect v1 (freenect://): it has an accelerometer, "
                      "no gyroscope and no wheels",
                      got);
  }
  throw ConfigError(
      file, key,
      std::string("camera for ") + (a.oni.empty() ? "this OpenNI2 camera" : "an .oni recording") +
          ": its streams are depth and colour only (motion readings come from sim:// devices, an "
          "accelerometer from a Kinect v1 on freenect://)",
      got);
}

namespace {

/// The settings' setup checked against the source; a Kinect's accelerometer
/// gets its description when the settings have none (docs/sensors.md).
void check_source_motion(const CameraArgs& a, const std::string& settings_file, slam::Settings* s) {
  if (a.sensors.empty())
    refuse_unfed_setup(a, s->motion.setup, settings_file, "System.Sensors");
  else
    refuse_unfed_setup(a, s->motion.setup, "command line", "--sensors");
  if (is_freenect_uri(a) && s->motion.setup == sensor::SensorSetup::kCameraAccel &&
      run::supply_kinect_description(s))
    std::fprintf(stderr,
                 "pvbench camera: note: sensors camera+accel: the settings have no IMU.* keys; the "
                 "Kinect v1 accelerometer's description is used (docs/sensors.md)\n");
}

}  // namespace

/// Files written into --out (no other output may land on one of them),
/// with a sim:// source's motion files.
const std::vector<std::string>& camera_output_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"camera.yaml", "CameraTrajectory.txt", "KeyFrameTrajectory.txt",
                                  "map.ply",     "stats.json",           "groundtruth.txt"};
    n.insert(n.end(), run::motion_output_names().begin(), run::motion_output_names().end());
    return n;
  }();
  return names;
}

/// The scenario of a sim:// source (with the URI's seed), else nullopt.  Also
/// checks an .oni input and where --record may write, before anything is
/// written: a recording never lands on an input or an output of the run.
std::optional<scenes::Scenario> check_inputs(const CameraArgs& a) {
  std::optional<scenes::Scenario> scenario;
  std::string scenario_path;
  if (a.oni.empty() && openni::is_sim_uri(a.uri)) {
    const openni::SimUri uri = openni::parse_sim_uri(a.uri);
    scenario = scenes::load_scenario(uri.scenario_path);
    if (uri.seed) scenario->seed = *uri.seed;
    scenario_path = uri.scenario_path;
  }
  if (!a.oni.empty()) openni::check_oni_complete(a.oni, openni::scan_oni_file(a.oni));
  if (!a.record.empty()) {
    std::vector<openni::RunFile> files = {
        {a.oni, "the --oni recording"}, {a.settings, "the --settings file"}, {scenario_path, "the scenario"}};
    for (std::string name : camera_output_names()) {
      if (name.back() == '/') name.pop_back();  // a folder of outputs
      files.push_back({a.out + "/" + name, "an output of this run"});
    }
    openni::check_record_not_on(a.record, files);
    openni::check_new_recording_path(a.record);  // before any device is open
  }
  return scenario;
}

/// The fakenect dump a freenect:// device plays when FAKENECT_PATH names one
/// (docs/openni.md); empty otherwise.  Its camera.yaml and groundtruth.txt,
/// written by `pvbench record --format fakenect`, stand in for a sim://
/// scenario's.
std::string fakenect_dump_dir(const CameraArgs& a) {
  const char* dir = std::getenv("FAKENECT_PATH");
  if (!a.oni.empty() || a.uri.rfind("freenect://", 0) != 0 || !dir || !*dir) return {};
  return dir;
}

bool readable(const std::string& path) { return static_cast<bool>(std::ifstream(path)); }


/// Where the settings will come from, checked before anything is written:
/// the user's file, a sim:// scenario, or a fakenect dump's camera.yaml.
void check_settings_source(const CameraArgs& a, const std::optional<scenes::Scenario>& scenario) {
  if (!a.settings.empty()) {
    require_regular_file(a.settings);
    return;
  }
  if (scenario) return;
  if (const std::string dump = fakenect_dump_dir(a); !dump.empty()) {
    dataset::read_fakenect_index(dump);  // a folder that is no dump says so, not that settings are missing
    if (readable(dump + "/camera.yaml")) return;
    throw ConfigError("pvbench camera", "--settings",
                      "a settings file with the camera's calibrated intrinsics (the fakenect dump " + dump +
                          " has no camera.yaml of its own)");
  }
  throw ConfigError("pvbench camera", "--settings",
                    "a settings file with the camera's calibrated intrinsics (only sim:// devices and fakenect dumps "
                    "have their own)");
}

bool is_freenect_uri(const CameraArgs& a) { return a.oni.empty() && a.uri.rfind("freenect://", 0) == 0; }

/// The settings, read before anything is written (camera.yaml is written
/// from `text` once the output folder is prepared).
CameraSettings read_camera_settings(const CameraArgs& a, const std::optional<scenes::Scenario>& scenario) {
  CameraSettings s;
  if (!a.settings.empty()) {
    s.file = a.settings;
  } else if (scenario) {
    dataset::OrbSlamSettings o = run::orbslam_settings_for(*scenario);
    o.depth_map_factor = 1000.0;  // OpenNI2 depth is in millimetres
    s.text = dataset::orbslam_settings_text(o);
    s.file = a.out + "/camera.yaml";
    s.slam = slam::read_settings_text(s.text, s.file);
  } else {  // a fakenect dump's own (check_settings_source)
    s.file = fakenect_dump_dir(a) + "/camera.yaml";
  }
  if (s.text.empty()) {
    s.text = read_file(s.file);
    s.slam = slam::read_settings(s.file);
  }
  for (const std::string& w : s.slam.warnings)
    std::fprintf(stderr, "pvbench camera: warning: %s\n", w.c_str());
  if (a.no_pe_match) s.slam.pe_match.enabled = false;
  if (const std::optional<sensor::SensorSetup> setup = sensors_from_flag(a.sensors)) s.slam.motion.setup = *setup;
  check_source_motion(a, s.file, &s.slam);
  run::apply_sensor_setup(&s.slam, s.slam.motion.setup);
  return s;
}

/// What camera reads and writes, checked before any device opens: no output
/// lands on the recording played, the settings, the scenario, a fakenect
/// dump's files or the map, and the recording on none of the outputs.
void check_camera_paths(const CameraArgs& a, const std::optional<scenes::Scenario>& scenario) {
  IoPlan plan;
  plan.input("the --oni recording", a.oni).input("the --settings file", a.settings);
  if (scenario) add_scenario_inputs(&plan, "sim:// scenario", *scenario);
  if (const std::string dump = fakenect_dump_dir(a); !dump.empty()) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dump, ec))
      if (e.is_regular_file(ec)) plan.input("a file of the fakenect dump (FAKENECT_PATH)", e.path().string());
  }
  plan.input("the --map file", a.map.load_path);
  plan.output_folder("--out", a.out, camera_output_names()).output_file("--save-map", a.map.save_path);
  plan.output_file("--record", a.record);
  plan.check();
  check_output_folder(a.out, a.overwrite);
  reserve_output(a.map.save_path, "--save-map");
}

openni::OpenniOptions source_options(const CameraArgs& a, const slam::Settings& settings, int timeout_ms) {
  openni::OpenniOptions so;
  so.uri = a.uri == "any" ? std::string() : a.uri;
  so.oni_path = a.oni;
  so.width = settings.K.width;
  so.height = settings.K.height;
  so.fps = static_cast<int>(std::lround(settings.fps));
  so.record_path = a.record;
  so.timeout_ms = timeout_ms;
  so.stop_requested = [] { return StopSignals::requested(); };  // Ctrl-C also ends a wait for frames
  return so;
}

}  // namespace pvb::cli::camera
