#include "pvb/report/world_json.hpp"

#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

std::string number8(double v) { return json_number(v, 8); }

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
  return "{\"latitude_deg\": " + number8(site.latitude_deg) +
         ", \"longitude_deg\": " + number8(site.longitude_deg) + ", \"date\": " + json_string(site.date) +
         ", \"time\": " + json_string(site.time) + ", \"utc_offset_h\": " + number8(site.utc_offset_h) + "}";
}

std::string array_json(const scenes::PvArray& a) {
  std::string out = "{\"mount\": ";
  if (a.mount == scenes::Mount::kSingleAxis) {
    out += "\"single_axis\", \"rotation_deg\": " + number8(a.rotation_deg) +
           ", \"ideal_rotation_deg\": " + number8(a.ideal_rotation_deg) +
           ", \"rotation_fixed\": " + (a.tracker.fixed_rotation_deg ? "true" : "false") +
           ", \"max_angle_deg\": " + number8(a.tracker.max_angle_deg) +
           ", \"backtrack\": " + (a.tracker.backtrack ? "true" : "false") +
           ", \"ground_coverage_ratio\": " + number8(a.ground_coverage_ratio());
  } else {
    out += "\"fixed\", \"tilt_deg\": " + number8(a.tilt_deg);
  }
  return out + ", \"dirt\": " + number8(a.dirt) + "}";
}

/// The ground, only when it is not the flat default: its relief (the
/// station's) and the soil's friction (the day's, or null).
std::string ground_json(const scenes::Ground& g) {
  std::string relief = "null";
  if (g.relief)
    relief = "{\"amplitude_cm\": " + number8(g.relief->amplitude_cm) + ", \"scale_m\": " + number8(g.relief->scale_m) +
             ", \"slope_percent\": " + number8(g.relief->slope_percent) +
             ", \"slope_azimuth_deg\": " + number8(g.relief->slope_azimuth_deg) +
             ", \"cell_m\": " + number8(g.relief->cell_m) + "}";
  return ", \"ground\": {\"relief\": " + relief +
         ", \"friction\": " + (g.friction ? number8(*g.friction) : std::string("null")) +
         ", \"softness\": " + number8(g.softness) + "}";
}

}  // namespace

std::string world_json(const scenes::Scenario& s) {
  std::string bases = "[";
  for (std::size_t i = 0; i < s.base_files.size(); ++i)
    bases += (i ? ", " : "") + json_string(s.base_files[i]);
  bases += "]";
  std::string arrays = "[";
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) arrays += (i ? ", " : "") + array_json(s.pv_arrays[i]);
  arrays += "]";
  return "{\"station_seed\": " + std::to_string(s.station_seed_or_seed()) +
         ", \"day_seed\": " + std::to_string(s.seed) + ", \"base_files\": " + bases +
         ", \"site\": " + (s.site ? site_json(*s.site) : std::string("null")) + ", \"sun\": {\"source\": \"" +
         source_name(s.sun.source) + "\", \"azimuth_deg\": " + number8(s.sun.solar_azimuth_deg) +
         ", \"elevation_deg\": " + number8(s.sun.elevation_deg) +
         ", \"scene_azimuth_deg\": " + number8(s.light.sun_azimuth_deg) +
         ", \"intensity\": " + number8(s.light.intensity) + ", \"ambient\": " + number8(s.light.ambient) +
         "}, \"vegetation_growth\": " + number8(s.vegetation.growth) + ", \"arrays\": " + arrays +
         (s.ground.relief || s.ground.governs_contact() ? ground_json(s.ground) : std::string()) + "}";
}

}  // namespace pvb::run
