#pragma once
// What the commands that take frames write into their --out folder, for
// their IoPlan: another output of the command (--save-map) that names one
// of these files is refused before any work (pvb/common/io_paths.hpp).
// Names as is_written_name() reads them: "stats.json", "imu0/" (a folder
// and all it holds), "*.png" (any name at the top of the folder).
#include <string>
#include <vector>

namespace pvb::run {

/// The motion files of a simulated source (dataset::MotionFilesWriter,
/// MotionTruthWriter, write_robot_truth): record, run and camera sim://.
const std::vector<std::string>& motion_output_names();

/// `pvbench run` (and each session of a campaign): the report, the
/// trajectories, the figures, the dense maps, the motion files and the
/// compared run's folder.
const std::vector<std::string>& run_output_names();

/// `pvbench slam`: trajectories, timing, stats, the dense maps and the
/// optional dumps.
const std::vector<std::string>& offline_slam_output_names();

}  // namespace pvb::run
