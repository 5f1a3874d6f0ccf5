// pvbench: simulation-in-the-loop test bench for visual SLAM on solar farms.
#include <cstdio>
#include <exception>
#include <opencv2/core/utils/logger.hpp>
#include <vector>

#include "command.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"

namespace pvb::cli {
Command add_record_command(CLI::App& app);
Command add_eval_command(CLI::App& app);
Command add_match_command(CLI::App& app);
Command add_slam_command(CLI::App& app);
#ifdef PVB_HAVE_OPENNI2
Command add_camera_command(CLI::App& app);
#endif
Command add_run_command(CLI::App& app);
Command add_check_command(CLI::App& app);
Command add_sweep_command(CLI::App& app);
Command add_map_check_command(CLI::App& app);
Command add_vocab_command(CLI::App& app);
Command add_eval_map_command(CLI::App& app);
Command add_sheet_command(CLI::App& app);
Command add_plan_command(CLI::App& app);
Command add_campaign_command(CLI::App& app);

/// Prints "pvbench: KIND: WHAT" and marks the output folders this process
/// began as failed; returns `code`.
int fail(int code, const char* kind, const std::string& what) {
  const std::string line = printable(what);
  std::fprintf(stderr, "pvbench: %s: %s\n", kind, line.c_str());
  mark_output_folders_failed(line);
  return code;
}

// Sub-commands register here (one line each).
std::vector<Command> add_all_commands(CLI::App& app) {
  std::vector<Command> cmds;
  cmds.push_back(add_record_command(app));
  cmds.push_back(add_eval_command(app));
  cmds.push_back(add_match_command(app));
  cmds.push_back(add_slam_command(app));
#ifdef PVB_HAVE_OPENNI2
  cmds.push_back(add_camera_command(app));
#endif
  cmds.push_back(add_run_command(app));
  cmds.push_back(add_campaign_command(app));
  cmds.push_back(add_check_command(app));
  cmds.push_back(add_sweep_command(app));
  cmds.push_back(add_map_check_command(app));
  cmds.push_back(add_vocab_command(app));
  cmds.push_back(add_eval_map_command(app));
  cmds.push_back(add_sheet_command(app));
  cmds.push_back(add_plan_command(app));
  return cmds;
}
}  // namespace pvb::cli

int main(int argc, char** argv) {
  CLI::App app{"pvbench: simulation-in-the-loop test bench for visual SLAM on solar farms"};
  app.set_version_flag("--version", std::string("pvbench ") + pvb::version());
  app.require_subcommand(1);
  std::vector<pvb::cli::Command> cmds = pvb::cli::add_all_commands(app);
  // pvbench reports bad input itself, one line each (a missing image is
  // "pvbench: warning: skipping frame ..."); OpenCV's own log would say it
  // again in its format.  Its errors still come through.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_ERROR);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const pvb::Error& e) {  // an option's own check (count_option.hpp)
    std::fprintf(stderr, "pvbench: error: %s\n", pvb::printable(e.what()).c_str());
    return 1;
  }
  // Every exception ends here as one line, a library's (OpenCV, Ceres,
  // yaml-cpp) too, and the output folders begun say the command failed.
  try {
    for (auto& c : cmds)
      if (c.app->parsed()) return c.run();
  } catch (const pvb::Error& e) {
    return pvb::cli::fail(1, "error", e.what());
  } catch (const std::exception& e) {
    return pvb::cli::fail(2, "internal error", e.what());
  } catch (...) {
    return pvb::cli::fail(2, "internal error", "an exception of unknown type");
  }
  return 0;
}
