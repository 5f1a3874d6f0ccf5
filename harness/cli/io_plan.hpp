#pragma once
// The inputs of the kinds several commands read, for their IoPlan (what a
// command reads and writes, checked before any work: io_paths.hpp).
#include <string>

#include "pvb/common/io_paths.hpp"
#include "pvb/dataset/tum_sequence.hpp"
#include "pvb/campaign/campaign.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::cli {

/// A scenario file and the files it derives from (base:).
inline void add_scenario_inputs(IoPlan* plan, const std::string& option, const scenes::Scenario& s) {
  plan->input("the " + option + " file", s.source_file)
      .inputs("a base of the " + option + " file", s.base_files);
}

/// The files of a TUM RGB-D folder a reader of it may read, and the folder
/// itself: a recording, which no output may land in.
inline void add_sequence_inputs(IoPlan* plan, const std::string& option, const std::string& dir) {
  if (dir.empty()) return;
  plan->inputs("a file of the " + option + " folder", dataset::sequence_files(dir));
  plan->input_folder("the " + option + " folder", dir);
}

/// A campaign file and every session's scenario with its bases.
inline void add_campaign_inputs(IoPlan* plan, const std::string& option, const run::Campaign& c) {
  plan->input("the " + option + " file", c.file);
  for (const run::CampaignSession& s : c.sessions)
    add_scenario_inputs(plan, "scenario of session " + s.name, scenes::load_scenario(s.scenario_file));
}

}  // namespace pvb::cli
