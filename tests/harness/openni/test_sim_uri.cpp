#include <gtest/gtest.h>

#include "pvb/common/error.hpp"
#include "pvb/openni/sim_uri.hpp"

using namespace pvb::openni;

TEST(SimUri, ParsesPathAndOptions) {
  EXPECT_TRUE(is_sim_uri("sim://a.yaml"));
  EXPECT_FALSE(is_sim_uri("/dev/x"));
  SimUri u = parse_sim_uri("sim://scenes/pv_station.yaml");
  EXPECT_EQ(u.scenario_path, "scenes/pv_station.yaml");
  EXPECT_FALSE(u.seed);
  EXPECT_EQ(u.frames, 0);
  EXPECT_EQ(u.stall_after, 0);
  u = parse_sim_uri("sim:///abs/x.yaml?seed=3&frames=20&gl=osmesa&unplug_after=5&stall_after=7");
  EXPECT_EQ(u.scenario_path, "/abs/x.yaml");
  EXPECT_EQ(*u.seed, 3u);
  EXPECT_EQ(u.frames, 20);
  EXPECT_EQ(u.gl, "osmesa");
  EXPECT_EQ(u.unplug_after, 5);
  EXPECT_EQ(u.stall_after, 7);
}

TEST(SimUri, RejectsMalformedUris) {
  EXPECT_THROW(parse_sim_uri("sim://"), pvb::ConfigError);
  EXPECT_THROW(parse_sim_uri("sim://a.yaml?frames=0"), pvb::ConfigError);
  EXPECT_THROW(parse_sim_uri("sim://a.yaml?frames=x"), pvb::ConfigError);
  EXPECT_THROW(parse_sim_uri("sim://a.yaml?colour=1"), pvb::ConfigError);
  EXPECT_THROW(parse_sim_uri("sim://a.yaml?gl=vulkan"), pvb::ConfigError);
  EXPECT_THROW(parse_sim_uri("sim://a.yaml?stall_after=0"), pvb::ConfigError);
  EXPECT_THROW(parse_sim_uri("file://a.yaml"), pvb::ConfigError);
  try {
    parse_sim_uri("sim://a.yaml?speed=2");
    FAIL();
  } catch (const pvb::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("speed"), std::string::npos) << e.what();
  }
}
