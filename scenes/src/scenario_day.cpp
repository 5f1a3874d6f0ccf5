// What a scenario's day makes of its station: the sun from the site and the
// local time (NOAA's algorithm, solar_position.hpp), its light, and the
// angle of every single-axis tracker (pvlib's singleaxis, tracker.hpp).
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/scenes/solar_position.hpp"
#include "pvb/scenes/tracker.hpp"
#include "scenario_sections.hpp"

namespace pvb::scenes {
namespace detail {
namespace {

constexpr double kDeg = M_PI / 180.0;

double wrap_360(double deg) {
  const double w = std::fmod(deg, 360.0);
  return w < 0 ? w + 360.0 : w;
}

/// Relative optical air mass at a zenith angle (Kasten and Young, Applied
/// Optics 28(22), 1989).
double air_mass(double zenith_deg) {
  return 1.0 / (std::cos(zenith_deg * kDeg) + 0.50572 * std::pow(96.07995 - zenith_deg, -1.6364));
}

/// The share of the sun's beam that reaches the ground through a clear sky
/// (Meinel and Meinel, "Applied Solar Energy", 1976): 0.7^(AM^0.678).
double beam_share(double elevation_deg) { return std::pow(0.7, std::pow(air_mass(90.0 - elevation_deg), 0.678)); }

/// Where `key` was written, for an error.
std::string where(const ReadContext& ctx, const std::string& key) { return ctx.origins->where(key, ctx.file); }

SolarPosition site_sun(const Scenario& s, const ReadContext& ctx) {
  const Site& site = *s.site;
  const CivilTimeParse t = parse_civil_time(site.date, site.time, site.utc_offset_h);
  const std::optional<SolarPosition> pos = solar_position(site.latitude_deg, site.longitude_deg, *t.time,
                                                          Atmosphere{site.pressure_hpa, site.temperature_c});
  if (!pos) throw ConfigError(where(ctx, "site"), "site", "a place and time the sun's position is defined for");
  return *pos;
}

/// The site's keys that put the sun where it is, as the most derived file
/// that gives any of them wrote them, and where the first was written:
/// site.time when that file gives the time, else the keys it gives ("site.
/// latitude_deg, site.date"): a derived file that moves the site or the
/// date is named, not the base that gave the time.
std::pair<std::string, std::string> sun_keys(const ReadContext& ctx) {
  static const char* const kKeys[] = {"latitude_deg", "longitude_deg", "date", "time", "utc_offset_h"};
  int depth = 1 << 30;
  for (const char* k : kKeys)
    if (const KeyOrigin* o = ctx.origins->find(std::string("site.") + k)) depth = std::min(depth, o->depth);
  const KeyOrigin* time = ctx.origins->find("site.time");
  if (!time || time->depth == depth) return {"site.time", where(ctx, "site.time")};
  std::string keys, at;
  for (const char* k : kKeys) {
    const KeyOrigin* o = ctx.origins->find(std::string("site.") + k);
    if (!o || o->depth != depth) continue;
    keys += (keys.empty() ? "site." : ", site.") + std::string(k);
    if (at.empty()) at = where(ctx, std::string("site.") + k);
  }
  return {keys, at};
}

/// The light follows the site's sun, except for what a file at least as
/// derived as the one that gives site: says itself (a base's light keys
/// are the base's day, not this one).
void resolve_sun_from_site(Scenario& s, const ReadContext& ctx) {
  const SolarPosition pos = site_sun(s, ctx);
  const int site_depth = ctx.origins->find("site")->depth;
  const auto from_site = [&](const char* key) {
    const KeyOrigin* o = ctx.origins->find(std::string("light.") + key);
    return o == nullptr || o->depth > site_depth;
  };
  Light& l = s.light;
  if (from_site("sun_elevation_deg")) {
    if (pos.elevation_deg < 1.0) {
      const auto [keys, at] = sun_keys(ctx);
      throw ConfigError(at, keys,
                        keys == "site.time"
                            ? "a time when the sun is up (at least 1 deg above the horizon at the site)"
                            : "a place and date where the sun is up at the site's time (at least 1 "
                              "deg above the horizon)",
                        "the sun " + format_number("%.1f deg", pos.elevation_deg) + " above the horizon at " +
                            format_exact(s.site->latitude_deg) + " deg N, " +
                            format_exact(s.site->longitude_deg) + " deg E on " + s.site->date + " at " +
                            s.site->time + " (UTC" + format_number("%+g", s.site->utc_offset_h) + ")");
    }
    l.sun_elevation_deg = pos.elevation_deg;
  }
  if (from_site("sun_azimuth_deg")) l.sun_azimuth_deg = scene_sun_azimuth_deg(pos.azimuth_deg);
  if (from_site("intensity")) l.intensity = sun_intensity_for(l.sun_elevation_deg);
  if (from_site("ambient")) l.ambient = sky_ambient_for(l.sun_elevation_deg);
  s.sun.source = SunPosition::Source::kSite;
}

void resolve_trackers(Scenario& s) {
  for (PvArray& a : s.pv_arrays) {
    if (a.mount != Mount::kSingleAxis) continue;
    if (a.tracker.fixed_rotation_deg) {
      a.rotation_deg = a.ideal_rotation_deg = *a.tracker.fixed_rotation_deg;
      continue;
    }
    SingleAxisTracker t;
    t.axis_azimuth_deg = wrap_360(90.0 - a.azimuth_deg);  // the tube along +u, as a compass bearing
    t.max_angle_deg = a.tracker.max_angle_deg;
    t.backtrack = a.tracker.backtrack;
    t.gcr = a.ground_coverage_ratio();
    const std::optional<TrackerRotation> r =
        tracker_rotation(90.0 - s.sun.elevation_deg, s.sun.solar_azimuth_deg, t);
    a.rotation_deg = r ? r->rotation_deg : 0.0;  // the sun is up (elevation >= 1 deg): always a value
    a.ideal_rotation_deg = r ? r->ideal_deg : 0.0;
  }
}

}  // namespace

void read_site(MapReader& top, Scenario& s) {
  const YAML::Node n = top.child("site");
  if (!n) return;
  MapReader r(n, top.context(), "site");
  for (const char* key : {"latitude_deg", "longitude_deg", "date", "time", "utc_offset_h"})
    if (!r.has(key)) r.fail(r.full(key), n, std::string("a value (required in site)"));
  Site site;
  site.latitude_deg = r.number("latitude_deg", 0, -90, 90);
  site.longitude_deg = r.number("longitude_deg", 0, -180, 180);
  site.date = r.string("date", "");
  site.time = r.string("time", "");
  site.utc_offset_h = r.number("utc_offset_h", 0, -12, 14);
  site.pressure_hpa = r.number("pressure_hpa", site.pressure_hpa, 300, 1200);
  site.temperature_c = r.number("temperature_c", site.temperature_c, -60, 60);
  r.finish();
  const CivilTimeParse t = parse_civil_time(site.date, site.time, site.utc_offset_h);
  if (!t.time) {
    const bool date_wrong = t.error.rfind("date", 0) == 0;
    const char* key = date_wrong ? "date" : "time";
    r.fail(r.full(key), n, date_wrong ? "a date YYYY-MM-DD (years 1901-2099)" : "a local time HH:MM or HH:MM:SS",
           t.error);
  }
  s.site = site;
}

void resolve_day(Scenario& s, const ReadContext& ctx) {
  if (s.site) {
    resolve_sun_from_site(s, ctx);
  } else {
    const bool written = ctx.origins->find("light.sun_azimuth_deg") || ctx.origins->find("light.sun_elevation_deg");
    s.sun.source = written ? SunPosition::Source::kLight : SunPosition::Source::kDefault;
  }
  s.sun.solar_azimuth_deg = wrap_360(90.0 - s.light.sun_azimuth_deg);
  s.sun.elevation_deg = s.light.sun_elevation_deg;
  resolve_trackers(s);
}

}  // namespace detail

double sun_intensity_for(double elevation_deg) {
  return std::clamp(0.8 * detail::beam_share(elevation_deg) / detail::beam_share(45.0), 0.05, 1.0);
}

double clear_sky_beam_share(double elevation_deg) {
  return elevation_deg > 0 ? detail::beam_share(std::min(elevation_deg, 90.0)) : 0.0;
}

double beam_relative_to_air_mass_15(double elevation_deg) {
  constexpr double kAirMass15ElevationDeg = 41.81;
  return clear_sky_beam_share(elevation_deg) / clear_sky_beam_share(kAirMass15ElevationDeg);
}

double sky_ambient_for(double elevation_deg) {
  const double sin_el = std::sin(std::clamp(elevation_deg, 0.0, 90.0) * detail::kDeg);
  return std::clamp(0.35 * (0.45 + 0.55 * sin_el / std::sin(45.0 * detail::kDeg)), 0.1, 0.6);
}

}  // namespace pvb::scenes
