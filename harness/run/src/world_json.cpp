#include "pvb/run/world_json.hpp"

#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

std::string str(const std::string& s) { return "\"" + json_escape(s) + "\""; }
std::string num(double v) { return json_number(v, 8); }

const char* source_name(scenes::SunPosition::Source s) {
  switch (s) {
    case scenes::SunPosition::Source::kSite:
      return "site";
    case scenes::SunPosition::Source::kLight:
      return "light";
    case scenes::SunPosition::Source::kDefault:
      break;
  }
  return "default";
}

std::string site_json(const scenes::Site& site) {
  return "{\"latitude_deg\": " + num(site.latitude_deg) + ", \"longitude_deg\": " + num(site.longitude_deg) +
         ", \"date\": " + str(site.date) + ", \"time\": " + str(site.time) +
         ", \"utc_offset_h\": " + num(site.utc_offset_h) + "}";
}

std::string array_json(const scenes::PvArray& a) {
  std::string out = "{\"mount\": ";
  if (a.mount == scenes::Mount::kSingleAxis) {
    out += "\"single_axis\", \"rotation_deg\": " + num(a.rotation_deg) +
           ", \"ideal_rotation_deg\": " + num(a.ideal_rotation_deg) +
           ", \"rotation_fixed\": " + (a.tracker.fixed_rotation_deg ? "true" : "false") +
           ", \"max_angle_deg\": " + num(a.tracker.max_angle_deg) +
           ", \"backtrack\": " + (a.tracker.backtrack ? "true" : "false") +
           ", \"ground_coverage_ratio\": " + num(a.ground_coverage_ratio());
  } else {
    out += "\"fixed\", \"tilt_deg\": " + num(a.tilt_deg);
  }
  return out + ", \"dirt\": " + num(a.dirt) + "}";
}

}  // namespace

std::string world_json(const scenes::Scenario& s) {
  std::string bases = "[";
  for (std::size_t i = 0; i < s.base_files.size(); ++i) bases += (i ? ", " : "") + str(s.base_files[i]);
  bases += "]";
  std::string arrays = "[";
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) arrays += (i ? ", " : "") + array_json(s.pv_arrays[i]);
  arrays += "]";
  return "{\"station_seed\": " + std::to_string(s.station_seed_or_seed()) +
         ", \"day_seed\": " + std::to_string(s.seed) + ", \"base_files\": " + bases +
         ", \"site\": " + (s.site ? site_json(*s.site) : std::string("null")) + ", \"sun\": {\"source\": \"" +
         source_name(s.sun.source) + "\", \"azimuth_deg\": " + num(s.sun.solar_azimuth_deg) +
         ", \"elevation_deg\": " + num(s.sun.elevation_deg) +
         ", \"scene_azimuth_deg\": " + num(s.light.sun_azimuth_deg) + ", \"intensity\": " + num(s.light.intensity) +
         ", \"ambient\": " + num(s.light.ambient) + "}, \"vegetation_growth\": " + num(s.vegetation.growth) +
         ", \"arrays\": " + arrays + "}";
}

}  // namespace pvb::run
