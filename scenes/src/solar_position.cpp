#include "pvb/scenes/solar_position.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "pvb/common/text.hpp"
#include "pvb/geometry/angles.hpp"

namespace pvb::scenes {
namespace {

using geom::cos_deg;
using geom::kDegToRad;
using geom::kRadToDeg;
using geom::sin_deg;
// NOAA's spreadsheet works on Excel dates, hence its stated validity range.
constexpr int kFirstYear = 1901;
constexpr int kLastYear = 2099;
constexpr std::array<const char*, 12> kMonthNames = {"January",   "February", "March",    "April",
                                                     "May",       "June",     "July",     "August",
                                                     "September", "October",  "November", "December"};

double tan_deg(double a) { return std::tan(a * kDegToRad); }

bool is_leap_year(int year) { return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0; }

int days_in_month(int year, int month) {
  constexpr std::array<int, 12> kDays = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  return month == 2 && is_leap_year(year) ? 29 : kDays[static_cast<std::size_t>(month - 1)];
}


std::optional<std::string> date_error(int year, int month, int day) {
  if (year < kFirstYear || year > kLastYear)
    return "year " + std::to_string(year) + " is outside " + std::to_string(kFirstYear) + ".." +
           std::to_string(kLastYear);
  if (month < 1 || month > 12) return "month " + std::to_string(month) + " is outside 1..12";
  const int last = days_in_month(year, month);
  if (day < 1 || day > last)
    return "day " + std::to_string(day) + " is outside " + kMonthNames[static_cast<std::size_t>(month - 1)] +
           " " + std::to_string(year) + " (1.." + std::to_string(last) + ")";
  return std::nullopt;
}

std::optional<std::string> clock_error(int hour, int minute, double second) {
  if (hour < 0 || hour > 23) return "hour " + std::to_string(hour) + " is outside 0..23";
  if (minute < 0 || minute > 59) return "minute " + std::to_string(minute) + " is outside 0..59";
  if (!(second >= 0.0 && second < 60.0)) return "second " + format_g(second) + " is outside [0, 60)";
  return std::nullopt;
}

std::optional<std::string> offset_error(double utc_offset_h) {
  if (!(utc_offset_h >= -12.0 && utc_offset_h <= 14.0))
    return "utc offset " + format_g(utc_offset_h) + " h is outside -12..14";
  return std::nullopt;
}

// Julian day of the instant (Meeus, ch. 7, Gregorian calendar); the day
// carries the UT time as a fraction, which may fall outside [0, 1) when the
// offset moves the instant into the day before or after: the formula is
// linear in the day.
double julian_day(const CivilTime& t) {
  int y = t.year, m = t.month;
  if (m <= 2) {
    y -= 1;
    m += 12;
  }
  const int a = y / 100;
  const int b = 2 - a + a / 4;
  const double ut_h = t.hour + t.minute / 60.0 + t.second / 3600.0 - t.utc_offset_h;
  return std::floor(365.25 * (y + 4716)) + std::floor(30.6001 * (m + 1)) + t.day + ut_h / 24.0 + b - 1524.5;
}

// Reads a run of digits of length min_len..max_len from s at *pos.
std::optional<int> read_digits(std::string_view s, std::size_t* pos, std::size_t min_len,
                               std::size_t max_len) {
  std::size_t n = 0;
  int v = 0;
  while (*pos + n < s.size() && n < max_len && s[*pos + n] >= '0' && s[*pos + n] <= '9') {
    v = v * 10 + (s[*pos + n] - '0');
    ++n;
  }
  if (n < min_len) return std::nullopt;
  *pos += n;
  return v;
}

bool read_char(std::string_view s, std::size_t* pos, char c) {
  if (*pos >= s.size() || s[*pos] != c) return false;
  ++*pos;
  return true;
}

// The sun's declination and the equation of time at a Julian day: the
// columns G..V of NOAA's spreadsheet (gml.noaa.gov/grad/solcalc/
// calcdetails.html), which follow Meeus, chapters 24 (low accuracy solar
// coordinates, about 0.01 degree), 21 (obliquity) and 27 (equation of time).
struct SunCoordinates {
  double declination_deg;
  double equation_of_time_min;
};

SunCoordinates sun_coordinates(double jd) {
  const double jc = (jd - 2451545.0) / 36525.0;  // Julian centuries from J2000.0
  const double mean_long = std::fmod(280.46646 + jc * (36000.76983 + jc * 0.0003032), 360.0);
  const double mean_anom = 357.52911 + jc * (35999.05029 - 0.0001537 * jc);
  const double ecc = 0.016708634 - jc * (0.000042037 + 0.0000001267 * jc);
  const double centre = sin_deg(mean_anom) * (1.914602 - jc * (0.004817 + 0.000014 * jc)) +
                        sin_deg(2 * mean_anom) * (0.019993 - 0.000101 * jc) +
                        sin_deg(3 * mean_anom) * 0.000289;
  const double true_long = mean_long + centre;
  // nutation and aberration, through the longitude of the Moon's node
  const double node = 125.04 - 1934.136 * jc;
  const double apparent_long = true_long - 0.00569 - 0.00478 * sin_deg(node);
  const double mean_obliquity =
      23.0 + (26.0 + (21.448 - jc * (46.815 + jc * (0.00059 - jc * 0.001813))) / 60.0) / 60.0;
  const double obliquity = mean_obliquity + 0.00256 * cos_deg(node);
  SunCoordinates out;
  out.declination_deg = std::asin(sin_deg(obliquity) * sin_deg(apparent_long)) * kRadToDeg;
  const double y = std::pow(tan_deg(obliquity / 2.0), 2);
  const double l2 = 2.0 * mean_long * kDegToRad, m = mean_anom * kDegToRad;
  const double eot_rad = y * std::sin(l2) - 2.0 * ecc * std::sin(m) +
                         4.0 * ecc * y * std::sin(m) * std::cos(l2) - 0.5 * y * y * std::sin(2.0 * l2) -
                         1.25 * ecc * ecc * std::sin(2.0 * m);
  out.equation_of_time_min = 4.0 * eot_rad * kRadToDeg;  // 4 minutes of time per degree
  return out;
}

// Atmospheric refraction (degrees) at a true elevation, as NOAA's spreadsheet
// computes it (column AF, arc seconds, after Saemundsson and Bennett), for
// 1010 hPa and 10 C; other conditions scale it by (P / 1010) (283 / (273 + T))
// (Meeus, ch. 16).
double refraction_deg(double true_elevation_deg, const Atmosphere& air) {
  const double e = true_elevation_deg;
  double arcsec = 0.0;
  if (e > 85.0) {
    arcsec = 0.0;
  } else if (e > 5.0) {
    const double t = tan_deg(e);
    arcsec = 58.1 / t - 0.07 / std::pow(t, 3) + 0.000086 / std::pow(t, 5);
  } else if (e > -0.575) {
    arcsec = 1735.0 + e * (-518.2 + e * (103.4 + e * (-12.79 + e * 0.711)));
  } else {
    arcsec = -20.772 / tan_deg(e);
  }
  const double scale = (air.pressure_hpa / 1010.0) * (283.0 / (273.0 + air.temperature_c));
  return arcsec / 3600.0 * scale;
}

}  // namespace

std::optional<std::string> civil_time_error(const CivilTime& t) {
  if (auto e = date_error(t.year, t.month, t.day)) return e;
  if (auto e = clock_error(t.hour, t.minute, t.second)) return e;
  return offset_error(t.utc_offset_h);
}

std::optional<std::string> solar_input_error(double latitude_deg, double longitude_deg, const CivilTime& t,
                                             const Atmosphere& air) {
  if (!(latitude_deg >= -90.0 && latitude_deg <= 90.0))
    return "latitude " + format_g(latitude_deg) + " deg is outside [-90, 90]";
  if (!(longitude_deg >= -180.0 && longitude_deg <= 180.0))
    return "longitude " + format_g(longitude_deg) + " deg is outside [-180, 180]";
  if (!(air.pressure_hpa > 0.0 && air.pressure_hpa <= 1200.0))
    return "pressure " + format_g(air.pressure_hpa) + " hPa is outside (0, 1200]";
  if (!(air.temperature_c > -100.0 && air.temperature_c < 60.0))
    return "temperature " + format_g(air.temperature_c) + " C is outside (-100, 60)";
  return civil_time_error(t);
}

CivilTimeParse parse_civil_time(std::string_view date, std::string_view clock, double utc_offset_h) {
  CivilTimeParse out;
  CivilTime t;
  t.utc_offset_h = utc_offset_h;
  std::size_t p = 0;
  const auto year = read_digits(date, &p, 4, 4);
  const bool dash1 = year && read_char(date, &p, '-');
  const auto month = dash1 ? read_digits(date, &p, 2, 2) : std::nullopt;
  const bool dash2 = month && read_char(date, &p, '-');
  const auto day = dash2 ? read_digits(date, &p, 2, 2) : std::nullopt;
  if (!day || p != date.size()) {
    out.error = "date '" + std::string(date) + "' is not YYYY-MM-DD";
    return out;
  }
  std::size_t q = 0;
  const auto hour = read_digits(clock, &q, 1, 2);
  const bool colon1 = hour && read_char(clock, &q, ':');
  const auto minute = colon1 ? read_digits(clock, &q, 2, 2) : std::nullopt;
  std::optional<int> second = 0;
  double fraction = 0.0;
  if (minute && read_char(clock, &q, ':')) {
    second = read_digits(clock, &q, 2, 2);
    if (second && read_char(clock, &q, '.')) {
      double scale = 0.1;
      const std::size_t start = q;
      for (; q < clock.size() && clock[q] >= '0' && clock[q] <= '9'; ++q, scale /= 10)
        fraction += (clock[q] - '0') * scale;
      if (q == start) second.reset();
    }
  }
  if (!minute || !second || q != clock.size()) {
    out.error = "time '" + std::string(clock) + "' is not HH:MM or HH:MM:SS";
    return out;
  }
  t.year = *year, t.month = *month, t.day = *day;
  t.hour = *hour, t.minute = *minute, t.second = *second + fraction;
  if (auto e = date_error(t.year, t.month, t.day)) {
    out.error = "date " + std::string(date) + ": " + *e;
  } else if (auto ce = clock_error(t.hour, t.minute, t.second)) {
    out.error = "time " + std::string(clock) + ": " + *ce;
  } else if (auto oe = offset_error(t.utc_offset_h)) {
    out.error = *oe;
  } else {
    out.time = t;
  }
  return out;
}

int day_of_year(const CivilTime& t) {
  int n = t.day;
  for (int m = 1; m < t.month; ++m) n += days_in_month(t.year, m);
  return n;
}

std::optional<SolarPosition> solar_position(double latitude_deg, double longitude_deg, const CivilTime& t,
                                            const Atmosphere& air) {
  if (solar_input_error(latitude_deg, longitude_deg, t, air)) return std::nullopt;
  SolarPosition out;
  out.julian_day = julian_day(t);
  const SunCoordinates sun = sun_coordinates(out.julian_day);
  out.declination_deg = sun.declination_deg;
  out.equation_of_time_min = sun.equation_of_time_min;
  // True solar time (minutes) and the hour angle, negative in the morning.
  const double ut_min = t.hour * 60.0 + t.minute + t.second / 60.0 - 60.0 * t.utc_offset_h;
  double hour_angle_deg =
      std::fmod((ut_min + sun.equation_of_time_min + 4.0 * longitude_deg) / 4.0, 360.0) - 180.0;
  if (hour_angle_deg < -180.0) hour_angle_deg += 360.0;
  const double lat = latitude_deg * kDegToRad, dec = sun.declination_deg * kDegToRad;
  const double h = hour_angle_deg * kDegToRad;
  const double cos_zenith = std::sin(lat) * std::sin(dec) + std::cos(lat) * std::cos(dec) * std::cos(h);
  const double true_zenith_deg = std::acos(std::clamp(cos_zenith, -1.0, 1.0)) * kRadToDeg;
  out.true_elevation_deg = 90.0 - true_zenith_deg;
  out.elevation_deg = out.true_elevation_deg + refraction_deg(out.true_elevation_deg, air);
  out.zenith_deg = 90.0 - out.elevation_deg;
  // Azimuth from the south, westward (Meeus, eq. 13.5, with tan(dec) times
  // cos(dec) to stay finite at the poles), then turned to from the north.
  // NOAA's acos form gives the same angle but loses precision near the zenith.
  const double from_south =
      std::atan2(std::sin(h) * std::cos(dec),
                 std::cos(h) * std::cos(dec) * std::sin(lat) - std::sin(dec) * std::cos(lat));
  out.azimuth_deg = std::fmod(from_south * kRadToDeg + 180.0 + 360.0, 360.0);
  return out;
}

double scene_sun_azimuth_deg(double solar_azimuth_deg) {
  // 90 - a, brought into (-180, 180]
  double a = std::fmod(90.0 - solar_azimuth_deg, 360.0);
  if (a <= -180.0) a += 360.0;
  if (a > 180.0) a -= 360.0;
  return a;
}

}  // namespace pvb::scenes
