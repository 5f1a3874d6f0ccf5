#include <gtest/gtest.h>

#include <cmath>

#include "pvb/scenes/solar_position.hpp"

using namespace pvb::scenes;

namespace {

// The accuracy asked of the sun's azimuth and elevation.  NOAA's equations
// (Meeus' low accuracy solar coordinates) are good to about 0.01 degree; the
// references below come from NREL's SPA (0.0003 degree).
constexpr double kAngleTolDeg = 0.1;
// The same accuracy as time: the sun moves 0.1 degree of hour angle in 0.4 min.
constexpr double kTimeTolMin = 0.4;

// Golden, Colorado: the site of the SPA report's example.
constexpr double kGoldenLatDeg = 39.742476;
constexpr double kGoldenLonDeg = -105.1786;

CivilTime at(int y, int mo, int d, int h, int mi, double s, double offset_h) {
  CivilTime t;
  t.year = y, t.month = mo, t.day = d, t.hour = h, t.minute = mi, t.second = s, t.utc_offset_h = offset_h;
  return t;
}

SolarPosition sun(double lat_deg, double lon_deg, const CivilTime& t, const Atmosphere& air = {}) {
  const auto p = solar_position(lat_deg, lon_deg, t, air);
  EXPECT_TRUE(p.has_value());
  return p.value_or(SolarPosition{});
}

// Smallest difference between two azimuths, in degrees.
double azimuth_diff_deg(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 360.0);
  return std::min(d, 360.0 - d);
}

// NREL's SPA rise and set are the instants the sun's centre is 0.8333 degree
// below the geometric horizon (0.26667 semi-diameter + 0.5667 refraction;
// Reda and Andreas 2004, A.2).
constexpr double kRiseSetTrueElevationDeg = -0.8333;

}  // namespace

// Reda and Andreas, "Solar Position Algorithm for Solar Radiation
// Applications", NREL/TP-560-34302 (2004), the worked example (A.5):
// 2003-10-17 12:30:30 local, UTC-7, Golden, 820 mbar, 11 C (elevation
// 1830.14 m: parallax, 0.0024 degree, is not modelled).  Topocentric zenith
// 50.11162, azimuth 194.34024, e0 39.872046 (without refraction), geocentric
// declination -9.31434, JD 2452930.312847 (also in pvlib tests/test_spa.py).
// Equation of time 14.64151 min: pvlib tests/test_solarposition.py,
// test_get_solarposition_pressure (pvlib's SPA, same instant and site).
TEST(SolarPosition, SpaReportExample) {
  const SolarPosition p = sun(kGoldenLatDeg, kGoldenLonDeg, at(2003, 10, 17, 12, 30, 30, -7), {820.0, 11.0});
  EXPECT_NEAR(p.julian_day, 2452930.312847, 1e-6);
  EXPECT_NEAR(p.zenith_deg, 50.11162, kAngleTolDeg);
  EXPECT_NEAR(p.elevation_deg, 90.0 - 50.11162, kAngleTolDeg);
  EXPECT_NEAR(p.azimuth_deg, 194.34024, kAngleTolDeg);
  EXPECT_NEAR(p.true_elevation_deg, 39.872046, kAngleTolDeg);
  EXPECT_NEAR(p.declination_deg, -9.31434, kAngleTolDeg);
  EXPECT_NEAR(p.equation_of_time_min, 14.64151, kTimeTolMin);
}

// pvlib tests/test_solarposition.py, expected_solpos_multi (NREL SPA): the
// day after the report's example, same time, site and air: apparent zenith
// 50.478260, azimuth 194.311132.
TEST(SolarPosition, SpaReportExampleNextDay) {
  const SolarPosition p = sun(kGoldenLatDeg, kGoldenLonDeg, at(2003, 10, 18, 12, 30, 30, -7), {820.0, 11.0});
  EXPECT_NEAR(p.zenith_deg, 50.478260, kAngleTolDeg);
  EXPECT_NEAR(p.azimuth_deg, 194.311132, kAngleTolDeg);
}

// NREL's SPA web calculator for Golden, MST (UTC-7), as quoted by pvlib
// tests/test_solarposition.py (expected_rise_set_spa, test_hour_angle):
// 2015-01-02 sunrise 07:21:55, transit 12:04:45, sunset 16:47:43, equation of
// time -3.935172, -4.026295, -4.117227 min; 2015-08-02 sunrise 05:00:27,
// transit 12:06:58.  At transit the sun is due south.  The calculator's
// 2015-08-02 sunset, 19:13:58, is not used: it is 63 s after the instant the
// sun's centre reaches -0.8333 degree here, where its other ten events in
// these tests agree within 1.1 s, and after the U.S. Naval Observatory's
// 19:13 (pvlib's expected_rise_set_ephem, "from USNO websites").  It is the
// only one of these events past the end of its UT date (02:14 UT), and
// SPA's rise and set procedure works from 0 h UT of the date (Reda and
// Andreas 2004, A.2).  USNO's 19:13 is used instead: rounded to the
// minute, +-30 s is +-0.09 degree at the sun's 0.17 degree/min.
TEST(SolarPosition, GoldenRiseTransitSetFromSpaCalculator) {
  const SolarPosition rise = sun(kGoldenLatDeg, kGoldenLonDeg, at(2015, 1, 2, 7, 21, 55, -7));
  const SolarPosition transit = sun(kGoldenLatDeg, kGoldenLonDeg, at(2015, 1, 2, 12, 4, 45, -7));
  const SolarPosition set = sun(kGoldenLatDeg, kGoldenLonDeg, at(2015, 1, 2, 16, 47, 43, -7));
  EXPECT_NEAR(rise.true_elevation_deg, kRiseSetTrueElevationDeg, kAngleTolDeg);
  EXPECT_NEAR(azimuth_diff_deg(transit.azimuth_deg, 180.0), 0.0, kAngleTolDeg);
  EXPECT_NEAR(set.true_elevation_deg, kRiseSetTrueElevationDeg, kAngleTolDeg);
  EXPECT_NEAR(rise.equation_of_time_min, -3.935172, kTimeTolMin);
  EXPECT_NEAR(transit.equation_of_time_min, -4.026295, kTimeTolMin);
  EXPECT_NEAR(set.equation_of_time_min, -4.117227, kTimeTolMin);
  EXPECT_LT(rise.azimuth_deg, 180.0);  // rises in the south-east in winter
  EXPECT_GT(set.azimuth_deg, 180.0);

  const SolarPosition summer_rise = sun(kGoldenLatDeg, kGoldenLonDeg, at(2015, 8, 2, 5, 0, 27, -7));
  const SolarPosition summer_transit = sun(kGoldenLatDeg, kGoldenLonDeg, at(2015, 8, 2, 12, 6, 58, -7));
  const SolarPosition summer_set = sun(kGoldenLatDeg, kGoldenLonDeg, at(2015, 8, 2, 19, 13, 0, -7));
  EXPECT_NEAR(summer_rise.true_elevation_deg, kRiseSetTrueElevationDeg, kAngleTolDeg);
  EXPECT_NEAR(azimuth_diff_deg(summer_transit.azimuth_deg, 180.0), 0.0, kAngleTolDeg);
  EXPECT_NEAR(summer_set.true_elevation_deg, kRiseSetTrueElevationDeg, kAngleTolDeg);
  EXPECT_LT(summer_rise.azimuth_deg, 90.0);  // rises north of east in summer
}

// NREL's SPA web calculator at 35 S, 0 E, UTC, as quoted by pvlib
// tests/test_solarposition.py (test_sun_rise_set_transit_spa): 1996-07-05
// sunrise 07:08:15, transit 12:04:36, sunset 17:01:04; 2004-12-04 sunrise
// 04:38:57, transit 11:50:22, sunset 19:02:03.  South of the tropic the sun
// culminates due north.
TEST(SolarPosition, SouthernHemisphereRiseTransitSetFromSpaCalculator) {
  struct Day {
    int y, mo, d;
    int rise_h, rise_m, rise_s, transit_h, transit_m, transit_s, set_h, set_m, set_s;
  };
  for (const Day& day :
       {Day{1996, 7, 5, 7, 8, 15, 12, 4, 36, 17, 1, 4}, Day{2004, 12, 4, 4, 38, 57, 11, 50, 22, 19, 2, 3}}) {
    SCOPED_TRACE(std::to_string(day.y));
    const SolarPosition rise =
        sun(-35.0, 0.0, at(day.y, day.mo, day.d, day.rise_h, day.rise_m, day.rise_s, 0));
    const SolarPosition transit =
        sun(-35.0, 0.0, at(day.y, day.mo, day.d, day.transit_h, day.transit_m, day.transit_s, 0));
    const SolarPosition set = sun(-35.0, 0.0, at(day.y, day.mo, day.d, day.set_h, day.set_m, day.set_s, 0));
    EXPECT_NEAR(rise.true_elevation_deg, kRiseSetTrueElevationDeg, kAngleTolDeg);
    EXPECT_NEAR(azimuth_diff_deg(transit.azimuth_deg, 0.0), 0.0, kAngleTolDeg);
    EXPECT_NEAR(set.true_elevation_deg, kRiseSetTrueElevationDeg, kAngleTolDeg);
    EXPECT_LT(rise.azimuth_deg, 180.0);
    EXPECT_GT(set.azimuth_deg, 180.0);
  }
}

// Meeus, "Astronomical Algorithms" (1991), example 25.a: 1992 October 13.0
// TD, apparent declination -7.78507 degree, by the low accuracy method that
// NOAA's equations follow (TD - UT, about 1 min, moves it by 0.0003 degree).
TEST(SolarPosition, MeeusExample25a) {
  const SolarPosition p = sun(0.0, 0.0, at(1992, 10, 13, 0, 0, 0, 0));
  EXPECT_NEAR(p.julian_day, 2448908.5, 1e-9);
  EXPECT_NEAR(p.declination_deg, -7.78507, 0.001);
}

// The refraction in the SPA report's example, 820 mbar and 11 C: e - e0 =
// 39.888378 - 39.872046 = 0.016332 degree (Reda and Andreas 2004, A.5); at
// 900 mbar 39.88997 - 39.87205 = 0.01792 (pvlib tests/test_solarposition.py,
// test_get_solarposition_pressure).  SPA uses Bennett's formula, NOAA its
// own fit; both are within 0.001 degree of each other at this elevation.
TEST(SolarPosition, RefractionFollowsPressure) {
  constexpr double kRefractionTolDeg = 0.001;
  const CivilTime t = at(2003, 10, 17, 12, 30, 30, -7);
  const SolarPosition thin = sun(kGoldenLatDeg, kGoldenLonDeg, t, {820.0, 11.0});
  const SolarPosition denser = sun(kGoldenLatDeg, kGoldenLonDeg, t, {900.0, 11.0});
  EXPECT_NEAR(thin.elevation_deg - thin.true_elevation_deg, 0.016332, kRefractionTolDeg);
  EXPECT_NEAR(denser.elevation_deg - denser.true_elevation_deg, 0.01792, kRefractionTolDeg);
}

TEST(SolarPosition, RefractionLiftsTheSunMoreInDenserAir) {
  const CivilTime t = at(2015, 1, 2, 7, 40, 0, -7);  // shortly after sunrise
  const SolarPosition standard = sun(kGoldenLatDeg, kGoldenLonDeg, t);
  const SolarPosition thin = sun(kGoldenLatDeg, kGoldenLonDeg, t, {820.0, 11.0});
  EXPECT_DOUBLE_EQ(standard.true_elevation_deg, thin.true_elevation_deg);
  EXPECT_GT(standard.elevation_deg - standard.true_elevation_deg,
            thin.elevation_deg - thin.true_elevation_deg);
  EXPECT_GT(thin.elevation_deg, thin.true_elevation_deg);
  EXPECT_NEAR(standard.zenith_deg, 90.0 - standard.elevation_deg, 1e-12);
}

TEST(SolarPosition, SameInstantInAnyTimeZone) {
  // 01:00 at UTC+2 is 23:00 UTC the day before
  const SolarPosition a = sun(48.0, 11.0, at(2026, 6, 21, 1, 0, 0, 2));
  const SolarPosition b = sun(48.0, 11.0, at(2026, 6, 20, 23, 0, 0, 0));
  EXPECT_NEAR(a.julian_day, b.julian_day, 1e-9);
  EXPECT_NEAR(a.azimuth_deg, b.azimuth_deg, 1e-9);
  EXPECT_NEAR(a.elevation_deg, b.elevation_deg, 1e-9);
}

TEST(SolarPosition, MorningSunIsInTheEastInBothHemispheres) {
  for (double lat : {-60.0, -20.0, 0.0, 20.0, 60.0}) {
    const SolarPosition morning = sun(lat, 0.0, at(2026, 3, 20, 8, 0, 0, 0));
    const SolarPosition afternoon = sun(lat, 0.0, at(2026, 3, 20, 16, 0, 0, 0));
    EXPECT_GT(morning.azimuth_deg, 0.0) << lat;
    EXPECT_LT(morning.azimuth_deg, 180.0) << lat;
    EXPECT_GT(afternoon.azimuth_deg, 180.0) << lat;
    EXPECT_GT(morning.elevation_deg, 0.0) << lat;
  }
}

TEST(SolarPosition, InvalidInputHasAReason) {
  const CivilTime ok = at(2026, 6, 21, 8, 0, 0, 2);
  EXPECT_FALSE(solar_input_error(45.0, 7.0, ok).has_value());
  EXPECT_FALSE(solar_position(91.0, 7.0, ok).has_value());
  EXPECT_NE(solar_input_error(91.0, 7.0, ok).value_or("").find("latitude 91"), std::string::npos);
  EXPECT_NE(solar_input_error(45.0, -181.0, ok).value_or("").find("longitude -181"), std::string::npos);
  EXPECT_NE(solar_input_error(45.0, 7.0, ok, {-5.0, 10.0}).value_or("").find("pressure"), std::string::npos);
  EXPECT_FALSE(solar_position(45.0, 7.0, at(2026, 2, 30, 8, 0, 0, 2)).has_value());
  EXPECT_EQ(civil_time_error(at(2026, 2, 29, 8, 0, 0, 0)).value_or(""),
            "day 29 is outside February 2026 (1..28)");
  EXPECT_FALSE(civil_time_error(at(2024, 2, 29, 8, 0, 0, 0)).has_value());  // leap year
  EXPECT_EQ(civil_time_error(at(2026, 13, 1, 8, 0, 0, 0)).value_or(""), "month 13 is outside 1..12");
  EXPECT_EQ(civil_time_error(at(2026, 1, 1, 8, 60, 0, 0)).value_or(""), "minute 60 is outside 0..59");
  EXPECT_EQ(civil_time_error(at(2026, 1, 1, 8, 0, 60, 0)).value_or(""), "second 60 is outside [0, 60)");
  EXPECT_EQ(civil_time_error(at(2026, 1, 1, 8, 0, 0, 15)).value_or(""), "utc offset 15 h is outside -12..14");
  EXPECT_EQ(civil_time_error(at(2100, 1, 1, 8, 0, 0, 0)).value_or(""), "year 2100 is outside 1901..2099");
}

TEST(SolarPosition, ParsesDateAndClock) {
  const CivilTimeParse p = parse_civil_time("2026-06-21", "08:00", 2.0);
  ASSERT_TRUE(p.time.has_value()) << p.error;
  EXPECT_TRUE(p.error.empty());
  EXPECT_EQ(p.time->year, 2026);
  EXPECT_EQ(p.time->month, 6);
  EXPECT_EQ(p.time->day, 21);
  EXPECT_EQ(p.time->hour, 8);
  EXPECT_EQ(p.time->minute, 0);
  EXPECT_EQ(p.time->second, 0.0);
  EXPECT_EQ(p.time->utc_offset_h, 2.0);
  const CivilTimeParse s = parse_civil_time("2003-10-17", "12:30:30.25", -7.0);
  ASSERT_TRUE(s.time.has_value()) << s.error;
  EXPECT_DOUBLE_EQ(s.time->second, 30.25);
  EXPECT_TRUE(parse_civil_time("2026-06-21", "8:05", 0.0).time.has_value());
}

TEST(SolarPosition, ParseErrorsAreOneLineWithTheText) {
  EXPECT_EQ(parse_civil_time("2026-02-30", "08:00", 0.0).error,
            "date 2026-02-30: day 30 is outside February 2026 (1..28)");
  EXPECT_EQ(parse_civil_time("2026-06-21", "25:00", 0.0).error, "time 25:00: hour 25 is outside 0..23");
  EXPECT_EQ(parse_civil_time("2026-6-21", "08:00", 0.0).error, "date '2026-6-21' is not YYYY-MM-DD");
  EXPECT_EQ(parse_civil_time("2026-06-21 ", "08:00", 0.0).error, "date '2026-06-21 ' is not YYYY-MM-DD");
  EXPECT_EQ(parse_civil_time("2026-06-21", "08h00", 0.0).error, "time '08h00' is not HH:MM or HH:MM:SS");
  EXPECT_EQ(parse_civil_time("2026-06-21", "08:00:", 0.0).error, "time '08:00:' is not HH:MM or HH:MM:SS");
  EXPECT_EQ(parse_civil_time("2026-06-21", "08:00:00.", 0.0).error,
            "time '08:00:00.' is not HH:MM or HH:MM:SS");
  EXPECT_EQ(parse_civil_time("2026-06-21", "08:00", -13.0).error, "utc offset -13 h is outside -12..14");
  EXPECT_FALSE(parse_civil_time("2026-02-30", "08:00", 0.0).time.has_value());
}

TEST(SolarPosition, DayOfYear) {
  EXPECT_EQ(day_of_year(at(2026, 1, 1, 0, 0, 0, 0)), 1);
  EXPECT_EQ(day_of_year(at(2026, 6, 21, 0, 0, 0, 0)), 172);
  EXPECT_EQ(day_of_year(at(2026, 12, 31, 0, 0, 0, 0)), 365);
  EXPECT_EQ(day_of_year(at(2024, 12, 31, 0, 0, 0, 0)), 366);
  EXPECT_EQ(day_of_year(at(2000, 3, 1, 0, 0, 0, 0)), 61);  // 2000 is a leap year (divisible by 400)
}

TEST(SolarPosition, SceneAzimuthIsCounterClockwiseFromEast) {
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(90.0), 0.0);     // east: world +x
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(0.0), 90.0);     // north: world +y
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(180.0), -90.0);  // south: world -y
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(270.0), 180.0);  // west: -180 wraps to 180
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(225.0), -135.0);
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(-45.0), 135.0);  // north-west
  EXPECT_DOUBLE_EQ(scene_sun_azimuth_deg(450.0), 0.0);
}
