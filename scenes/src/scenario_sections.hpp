#pragma once
// The readers of a scenario's sections and the checks between them, used by
// the loader (scenario.cpp).
#include <vector>

#include "map_reader.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::scenes::detail {

/// The renderer keeps room for every geom of the model and draws those in
/// the camera's view (sim/src/renderer.cpp), so the limit is what MuJoCo
/// compiles in seconds: a plant of four 10 MW blocks (about 18 300 geoms)
/// set up in 4.2 s, while 50 x 50 tables of 240 panels (617 500 geoms)
/// were not compiled after 5 minutes.
inline constexpr long long kMaxSceneGeoms = 20000;
/// A file's list of arrays or walls longer than this is refused before its
/// entries are read: a hand-written station has far fewer, and reading a
/// file of 200 000 walls took 20 s and 1.1 GB (a plant's inverter stations
/// are walls it makes, not a list).
inline constexpr long long kMaxListEntries = 3800;
/// The longest a scenario runs, and the latest time an event in it may
/// start: 12 h, a robot's working day.
inline constexpr double kMaxScenarioTime_s = 43200;

/// The ground: section (type, size, tiling, relief, the soil's friction).
void read_ground(MapReader& r, Ground& g);
void read_arrays(MapReader& top, std::vector<PvArray>& out);
void read_walls(MapReader& top, std::vector<Wall>& out);
/// A pv array's mount: fixed tables or a single-axis tracker (`mount`,
/// `tilt_deg`, `rails`, `tracker`).
void read_mount(MapReader& r, PvArray& a);
/// The plant: section: its blocks go after the scenario's arrays, its
/// inverter stations after its walls.  After ground: (the plant must lie
/// on it), pv_arrays and walls.
void read_plant(MapReader& top, Scenario& s);
/// A plant's route keeps this far from every table: the robot's half width.
inline constexpr double kRouteTableClearanceM = 0.30;
/// Refuses a plant's route that leaves the plant or runs through a table.
void check_plant_route(const Scenario& s, const ReadContext& ctx);
/// The keys of a route that needs a plant (a loop along its roads, a route
/// from its dock), checked before the route is drawn.
void check_plant_pattern(const Scenario& s, const ReadContext& ctx);
void read_vegetation(MapReader& r, Vegetation& v);
void read_light(MapReader& r, Light& l);
void read_route(MapReader& r, Route& rt);
void read_robot(MapReader& r, Robot& rb);
void read_camera(MapReader& r, Camera& c);
void read_slam(MapReader& r, SlamTuning& t);
void read_expect(MapReader& r, Expectations& e);
/// The kidnap: section.  Read after duration_s and camera, which bound it.
void read_kidnap(MapReader& top, Scenario& s);
/// The cover: section.  Read after kidnap: (a scenario has one or the
/// other), duration_s and camera.
void read_cover(MapReader& top, Scenario& s);
/// The physics:, imu: and wheels: sections.  Read after camera (the
/// physics rate is a multiple of its frame rate).
void read_body(MapReader& top, Scenario& s);
/// The site: section (the station's place and the run's local time).
void read_site(MapReader& top, Scenario& s);

/// The sun of the day (from site: and light:), its light, and every
/// tracker's rotation.  After every section is read.
void resolve_day(Scenario& s, const ReadContext& ctx);

/// Refuses a scenario whose scene would not fit the renderer: one line naming
/// the limit, the total and the largest array.
void check_scene_size(const Scenario& s, const ReadContext& ctx);
/// Checks between fields: the route against the arrays it names.
void check_route(const Scenario& s, const ReadContext& ctx);
/// Refuses bounds on the blind stretch in a scenario without covered frames.
void check_blind_bounds(const Scenario& s, const ReadContext& ctx);
/// Refuses a ground relief too rough or steep for the robot on its route.
void check_ground_relief(const Scenario& s, const ReadContext& ctx);

}  // namespace pvb::scenes::detail
