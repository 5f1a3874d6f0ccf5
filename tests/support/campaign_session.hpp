#pragma once
// A session of a campaign.json by name (tests of pvbench campaign).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <string>

namespace pvb::test {

inline YAML::Node campaign_session(const YAML::Node& campaign, const std::string& name) {
  for (const auto& s : campaign["sessions"])
    if (s["name"].as<std::string>() == name) return s;
  ADD_FAILURE() << "no session " << name;
  return {};
}

}  // namespace pvb::test
