// The scene-size check of a scenario: the geoms the scene builder will make
// for what the file asks for, against what MuJoCo's renderer draws.
#include <algorithm>

#include "pvb/common/error.hpp"
#include "pvb/scenes/plant.hpp"
#include "scenario_sections.hpp"

namespace pvb::scenes::detail {

/// Geoms the scene builder makes for what the scenario asks for (keep in step
/// with sim/src/scene_builder.cpp): per table its panels, one backsheet, two
/// rails and four posts; one per wall; two per shrub or tree.  The ground and
/// the robot add about ten.
long long table_geoms(const PvArray& a) {
  const long long panels = a.panel_slabs ? 1 : static_cast<long long>(a.panels_per_table) * a.panel_lines;
  // A tracker table: its panels, one backsheet, the torque tube and two posts.
  if (a.mount == Mount::kSingleAxis) return panels + 2 + (a.posts ? 2 : 0);
  const long long backsheet = 1, rails = a.rails ? 2 : 0, posts = a.posts ? 4 : 0;
  return panels + backsheet + rails + posts;
}

/// At most the geoms that missing modules add: a table that lost one is
/// drawn a module at a time, each module with its backsheet, instead of
/// one slab and one backsheet (every missing module in a table of its own
/// at worst).
long long missing_module_geoms(const PvArray& a) {
  if (a.missing_modules == 0) return 0;
  const long long modules = static_cast<long long>(a.panels_per_table) * a.panel_lines;
  return static_cast<long long>(a.missing_modules) * std::max(2 * modules - 4, 0LL);
}

/// ", up to N more for M missing modules a block" where a plant's blocks miss modules.
std::string missing_modules_part(const PlantSummary& p, const PvArray& block) {
  if (block.missing_modules == 0) return "";
  return ", up to " + std::to_string(p.blocks * missing_module_geoms(block)) + " more for " +
         std::to_string(block.missing_modules) + " missing modules a block";
}

/// At most kMaxSceneGeoms geoms: what MuJoCo's compiler builds in seconds
/// (scenario_sections.hpp); the renderer draws the ones in view.
///
/// Refuses a scenario whose scene would be larger: one line naming the
/// limit, the total and the largest array.
void check_scene_size(const Scenario& s, const ReadContext& ctx) {
  long long total = 2LL * (s.vegetation.shrubs + s.vegetation.trees) + static_cast<long long>(s.walls.size());
  if (s.plant) {  // a fixture is one geom, a fence section one
    total += static_cast<long long>(s.plant->fixtures.size() + 2 * s.plant->row_signs.size());
    total += static_cast<long long>(s.plant->blocks) * (2 * s.plant->tracked_aisles + s.plant->grass_rows);
    if (s.plant->fence) total += static_cast<long long>(fence_sections(*s.plant->fence).size());
  }
  long long largest = -1;
  std::size_t largest_index = 0;
  for (std::size_t i = 0; i < s.pv_arrays.size(); ++i) {
    const PvArray& a = s.pv_arrays[i];
    const long long n = static_cast<long long>(a.rows) * a.tables_per_row * table_geoms(a) +
                        a.broken_modules + missing_module_geoms(a);
    total += n;
    if (n > largest) {
      largest = n;
      largest_index = i;
    }
  }
  if (total <= kMaxSceneGeoms) return;
  std::string got = std::to_string(total);
  if (s.plant) {
    const PvArray& b = s.pv_arrays[static_cast<std::size_t>(s.plant->first_array)];
    throw ConfigError(
        ctx.origins->where("plant", ctx.file), "plant",
        "at most " + std::to_string(kMaxSceneGeoms) +
            " geoms in the scene (a plant's table is its slab and up to 7 parts; a wall, a fixture or "
            "40 m of fence 1, a shrub, a tree or a row sign 2): fewer blocks or rows",
        got + " (" + std::to_string(s.plant->blocks) + " blocks x " + std::to_string(b.rows) + " rows x " +
            std::to_string(b.tables_per_row) + " tables x " + std::to_string(table_geoms(b)) + " geoms" +
            missing_modules_part(*s.plant, b) + ")");
  }
  if (largest >= 0) {
    const PvArray& a = s.pv_arrays[largest_index];
    got += " (pv_arrays[" + std::to_string(largest_index) + "]: " + std::to_string(a.rows) + " rows x " +
           std::to_string(a.tables_per_row) + " tables x " + std::to_string(table_geoms(a)) + " geoms)";
  }
  throw ConfigError(ctx.origins->where("pv_arrays", ctx.file), "pv_arrays",
                    "at most " + std::to_string(kMaxSceneGeoms) +
                        " geoms in the scene (what MuJoCo compiles in seconds; a table is panels_per_table x "
                        "panel_lines panels + up to 7 parts, a wall 1, a shrub or tree 2)",
                    got);
}

}  // namespace pvb::scenes::detail
