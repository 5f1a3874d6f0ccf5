#pragma once
// Where the sun is, seen from a place on Earth at a local civil time: NOAA's
// solar position equations (the NOAA Solar Calculator and its spreadsheet,
// gml.noaa.gov/grad/solcalc/calcdetails.html, after Meeus, "Astronomical
// Algorithms", 1991).  Pure functions, no state; docs/sun_and_trackers.md
// gives the conventions, the accuracy and the reference values.
#include <optional>
#include <string>
#include <string_view>

namespace pvb::scenes {

/// A local civil date and time and the offset of its time zone from UTC
/// (local = UTC + utc_offset_h; daylight saving time is part of the offset,
/// e.g. +2 for summer time in central Europe).  Gregorian calendar.
struct CivilTime {
  int year = 2000;
  int month = 1;              ///< 1..12
  int day = 1;                ///< 1..days in the month
  int hour = 12;              ///< 0..23
  int minute = 0;             ///< 0..59
  double second = 0.0;        ///< [0, 60): leap seconds are not represented
  double utc_offset_h = 0.0;  ///< [-12, 14], the offsets in use on Earth
};

/// The air that bends the sun's light near the horizon.  The defaults are the
/// standard conditions that NOAA's refraction formula is written for.
struct Atmosphere {
  double pressure_hpa = 1010.0;  ///< (0, 1200]; 1 hPa = 1 mbar
  double temperature_c = 10.0;   ///< (-100, 60)
};

/// The sun seen from the ground.  Angles in degrees.
struct SolarPosition {
  double azimuth_deg = 0.0;           ///< clockwise from geographic north, [0, 360)
  double elevation_deg = 0.0;         ///< apparent: above the horizon, with refraction
  double zenith_deg = 0.0;            ///< apparent: 90 - elevation_deg
  double true_elevation_deg = 0.0;    ///< geometric, without refraction
  double declination_deg = 0.0;       ///< of the sun, geocentric apparent
  double equation_of_time_min = 0.0;  ///< apparent minus mean solar time
  double julian_day = 0.0;            ///< of the instant, in UT
};

/// Why `t` is not a valid civil time, in one line ("day 30 is outside
/// February 2026 (1..28)", "hour 25 is outside 0..23"), or nullopt when it
/// is.  Years 1901..2099, the range NOAA states for its spreadsheet.
std::optional<std::string> civil_time_error(const CivilTime& t);

/// Why the inputs of solar_position() are invalid (the civil time, latitude
/// outside [-90, 90], longitude outside [-180, 180], the atmosphere outside
/// its ranges), or nullopt when they are valid.
std::optional<std::string> solar_input_error(double latitude_deg, double longitude_deg, const CivilTime& t,
                                             const Atmosphere& air = {});

/// A civil time read from a date "YYYY-MM-DD" and a clock time "HH:MM" or
/// "HH:MM:SS" (seconds may carry a fraction), or the reason it cannot be read
/// (malformed text, or a value out of range as civil_time_error() says,
/// prefixed by the text: "date 2026-02-30: day 30 is outside February 2026
/// (1..28)").
struct CivilTimeParse {
  std::optional<CivilTime> time;
  std::string error;  ///< empty when `time` holds a value
};
CivilTimeParse parse_civil_time(std::string_view date, std::string_view clock, double utc_offset_h);

/// Day of the year, 1 for 1 January .. 365 or 366.  `t` must be valid.
int day_of_year(const CivilTime& t);

/// The sun's position for an observer at latitude_deg (north positive) and
/// longitude_deg (east positive) at local time `t`; nullopt when
/// solar_input_error() has a reason.  Geocentric (parallax, at most 0.0024
/// degree, is ignored) and UT is taken for TT (about 70 s, 0.001 degree of
/// solar longitude).
std::optional<SolarPosition> solar_position(double latitude_deg, double longitude_deg, const CivilTime& t,
                                            const Atmosphere& air = {});

/// The scene's sun azimuth (counter-clockwise from world +x, in (-180, 180])
/// for a solar azimuth (clockwise from north), taking world +x as east and
/// +y as north: 90 - solar_azimuth_deg, wrapped.
double scene_sun_azimuth_deg(double solar_azimuth_deg);

}  // namespace pvb::scenes
