#pragma once
// pvbench camera's inputs and settings, checked before any device opens or
// anything is written: the options, the files a run writes into --out, the
// scenario of a sim:// source, a fakenect dump's own files, where the
// settings come from, and what the source can feed the sensor setup.
#include <optional>
#include <string>
#include <vector>

#include "map_options.hpp"
#include "pvb/openni/openni_source.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/slam/core/settings.hpp"

namespace pvb::cli::camera {

struct CameraArgs {
  std::string uri;
  std::string oni;
  std::string settings;
  std::string out;
  bool overwrite = false;
  std::string record;
  std::string frames = "0";  ///< checked by parse_count: 0 = until the stream ends
  bool sync = false;
  std::uint32_t seed = 1;
  bool no_pe_match = false;
  std::string timeout_ms = "10000";  ///< checked by parse_count
  run::MapOptions map;
  std::string map_mode;
  std::string sensors;  ///< --sensors
};

/// Files written into --out (no other output may land on one of them),
/// with a sim:// source's motion files.
const std::vector<std::string>& camera_output_names();

/// The scenario of a sim:// source (with the URI's seed), else nullopt.  Also
/// checks an .oni input and where --record may write, before anything is
/// written: a recording never lands on an input or an output of the run.
std::optional<scenes::Scenario> check_inputs(const CameraArgs& a);

/// The fakenect dump a freenect:// device plays when FAKENECT_PATH names one
/// (docs/openni.md); empty otherwise.  Its camera.yaml and groundtruth.txt,
/// written by `pvbench record --format fakenect`, stand in for a sim://
/// scenario's.
std::string fakenect_dump_dir(const CameraArgs& a);

bool readable(const std::string& path);
bool is_freenect_uri(const CameraArgs& a);

/// What a source gives SLAM beside images, against the sensor setup: a
/// sim:// device its robot's IMU and encoders, a Kinect v1 (freenect://)
/// its accelerometer, an .oni recording or another OpenNI2 camera nothing.
/// A setup that needs more is refused (`file`, `key`: where it was asked
/// for) before any device opens.
void refuse_unfed_setup(const CameraArgs& a, sensor::SensorSetup setup, const std::string& file,
                        const std::string& key);

/// The SLAM settings and the file they came from (the one named in errors):
/// the user's --settings, the scenario's camera for sim:// sources, or a
/// fakenect dump's camera.yaml.  The file used is saved as camera.yaml;
/// intrinsics never come from the driver.
struct CameraSettings {
  slam::Settings slam;
  std::string file;
  std::string text;  ///< saved as camera.yaml once the folder is prepared
};

/// Where the settings will come from, checked before anything is written:
/// the user's file, a sim:// scenario, or a fakenect dump's camera.yaml.
void check_settings_source(const CameraArgs& a, const std::optional<scenes::Scenario>& scenario);

/// The settings, read before anything is written (camera.yaml is written
/// from `text` once the output folder is prepared), with the sensor setup
/// checked against what the source can feed.
CameraSettings read_camera_settings(const CameraArgs& a, const std::optional<scenes::Scenario>& scenario);

/// What camera reads and writes, checked before any device opens: no output
/// lands on the recording played, the settings, the scenario, a fakenect
/// dump's files or the map, and the recording on none of the outputs.
void check_camera_paths(const CameraArgs& a, const std::optional<scenes::Scenario>& scenario);

/// The OpenNI2 source's options for these settings.
openni::OpenniOptions source_options(const CameraArgs& a, const slam::Settings& settings, int timeout_ms);

}  // namespace pvb::cli::camera
