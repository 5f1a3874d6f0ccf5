// A plant's fixtures in the scene: the perimeter fence (posts, wires and
// gates as one mesh a section), the dock, the combiner boxes and the row
// signs (a post and a plate with the row's number).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "pvb/scenes/plant.hpp"
#include "pvb/sim/textures.hpp"
#include "scene_mjcf.hpp"
#include "splitmix.hpp"

namespace pvb::sim::mjcf {
namespace {

/// Line posts, the top rail and the two line wires, the gates' posts and tubes.
constexpr double kLinePostM = 0.06, kGatePostM = 0.12, kTopRailM = 0.04, kWireM = 0.02, kGateTubeM = 0.04;

/// One section's triangles, vertices relative to the section's start.
struct FenceMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> faces;

  /// A box around the segment p0 -> p1 with half extents e1 and e2 across it.
  void bar(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2) {
    const Eigen::Vector3d c = 0.5 * (p0 + p1), h = 0.5 * (p1 - p0);
    const Eigen::Vector3d axes[3] = {h, e1, e2};
    for (int axis = 0; axis < 3; ++axis)
      for (const double side : {-1.0, 1.0}) {
        const Eigen::Vector3d n = side * axes[axis], a = axes[(axis + 1) % 3], b = axes[(axis + 2) % 3];
        std::array<Eigen::Vector3d, 4> q = {c + n - a - b, c + n + a - b, c + n + a + b, c + n - a + b};
        if ((q[1] - q[0]).cross(q[2] - q[0]).dot(n) < 0) std::swap(q[1], q[3]);  // counter-clockwise from outside
        const int base = static_cast<int>(vertices.size());
        vertices.insert(vertices.end(), q.begin(), q.end());
        faces.push_back({base, base + 1, base + 2});
        faces.push_back({base, base + 2, base + 3});
      }
  }
};

/// Builds one side of the fence (corner a to corner b) into the meshes of
/// its sections: posts, and rails between them, except across a gate,
/// which gets heavier posts and a frame of tubes.
struct FenceSide {
  const scenes::Fence& fence;
  const scenes::GroundRelief& ground;
  Eigen::Vector2d a, b;
  std::vector<FenceMesh>* sections;  ///< this side's, equal lengths from a
  std::vector<Eigen::Vector2d> starts;

  double length() const { return (b - a).norm(); }
  Eigen::Vector2d at(double t) const { return a + (b - a) * (t / length()); }
  Eigen::Vector3d point(double t, double above_m) const {
    const Eigen::Vector2d p = at(t);
    return {p.x(), p.y(), ground.height_m(p) + above_m};
  }
  FenceMesh& section(double t) {
    const int n = static_cast<int>(sections->size());
    return (*sections)[static_cast<std::size_t>(std::clamp(static_cast<int>(t / length() * n), 0, n - 1))];
  }
  Eigen::Vector3d local(double t, const Eigen::Vector3d& p) {
    const int n = static_cast<int>(sections->size());
    const Eigen::Vector2d s0 = starts[static_cast<std::size_t>(std::clamp(static_cast<int>(t / length() * n), 0, n - 1))];
    return p - Eigen::Vector3d(s0.x(), s0.y(), 0);
  }
  void post(double t, double width_m) {
    const Eigen::Vector2d d = (b - a).normalized(), nrm(-d.y(), d.x());
    const double into = ground.flat() ? 0.0 : kIntoReliefM;
    section(t).bar(local(t, point(t, -into)), local(t, point(t, fence.height_m)),
                   Eigen::Vector3d(d.x(), d.y(), 0) * width_m / 2, Eigen::Vector3d(nrm.x(), nrm.y(), 0) * width_m / 2);
  }
  void rail(double t0, double t1, double above_m, double thick_m) {
    const Eigen::Vector2d d = (b - a).normalized(), nrm(-d.y(), d.x());
    const double tm = 0.5 * (t0 + t1);
    section(tm).bar(local(tm, point(t0, above_m)), local(tm, point(t1, above_m)), Eigen::Vector3d(0, 0, thick_m / 2),
                    Eigen::Vector3d(nrm.x(), nrm.y(), 0) * thick_m / 2);
  }
  void gate(double t0, double t1) {
    post(t0, kGatePostM);
    post(t1, kGatePostM);
    const double g0 = t0 + kGatePostM, g1 = t1 - kGatePostM, h = fence.height_m;
    for (const double z : {0.15, 0.5 * h, h - 0.05}) rail(g0, g1, z, kGateTubeM);
    const Eigen::Vector2d d = (b - a).normalized(), nrm(-d.y(), d.x());
    for (const double t : {g0, 0.5 * (t0 + t1), g1})
      section(t).bar(local(t, point(t, 0.15)), local(t, point(t, h - 0.05)),
                     Eigen::Vector3d(d.x(), d.y(), 0) * kGateTubeM / 2, Eigen::Vector3d(nrm.x(), nrm.y(), 0) * kGateTubeM / 2);
  }

  /// Posts at an even spacing of at most post_spacing_m, three rails
  /// between each pair, gates where the fence has them on this side.
  void build() {
    const double len = length(), half_gate = fence.gate_width_m / 2;
    std::vector<std::pair<double, double>> gates;
    const Eigen::Vector2d d = (b - a) / len;
    for (const Eigen::Vector2d& g : fence.gates_m) {
      const double t = (g - a).dot(d), off = std::abs((g - a).x() * d.y() - (g - a).y() * d.x());
      if (off < 0.01 && t > half_gate && t < len - half_gate) gates.emplace_back(t - half_gate, t + half_gate);
    }
    const auto in_gate = [&](double t) {
      return std::any_of(gates.begin(), gates.end(), [&](const auto& g) { return t > g.first - 0.3 && t < g.second + 0.3; });
    };
    const int n = std::max(1, static_cast<int>(std::ceil(len / fence.post_spacing_m - 1e-9)));
    std::vector<double> posts;
    for (int k = 0; k <= n; ++k)
      if (!in_gate(len * k / n)) posts.push_back(len * k / n);
    for (const auto& g : gates) posts.insert(std::upper_bound(posts.begin(), posts.end(), g.first), {g.first, g.second});
    for (std::size_t i = 0; i < posts.size(); ++i) {
      const bool gate_post = std::any_of(gates.begin(), gates.end(),
                                         [&](const auto& g) { return posts[i] == g.first || posts[i] == g.second; });
      if (!gate_post) post(posts[i], kLinePostM);
      if (i + 1 == posts.size()) continue;
      const bool across_gate = std::any_of(gates.begin(), gates.end(),
                                           [&](const auto& g) { return posts[i] == g.first && posts[i + 1] == g.second; });
      if (across_gate) continue;
      rail(posts[i], posts[i + 1], fence.height_m - kTopRailM / 2, kTopRailM);
      for (const double z : {0.6 * fence.height_m, 0.15}) rail(posts[i], posts[i + 1], z, kWireM);
    }
    for (const auto& g : gates) gate(g.first, g.second);
  }
};

/// The fence's sections, in the order of scenes::fence_sections.
std::vector<std::pair<Eigen::Vector2d, FenceMesh>> fence_meshes(const scenes::Fence& fence,
                                                                 const scenes::GroundRelief& ground) {
  std::vector<std::pair<Eigen::Vector2d, FenceMesh>> out;
  for (std::size_t i = 0; i < fence.corners_m.size(); ++i) {
    const Eigen::Vector2d a = fence.corners_m[i], b = fence.corners_m[(i + 1) % fence.corners_m.size()];
    // The sections of scenes::fence_sections: equal parts of the side.
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / scenes::kFenceSectionM - 1e-9)));
    std::vector<FenceMesh> meshes(static_cast<std::size_t>(n));
    std::vector<Eigen::Vector2d> starts;
    for (int k = 0; k < n; ++k) starts.push_back(a + (b - a) * (static_cast<double>(k) / n));
    FenceSide side{fence, ground, a, b, &meshes, starts};
    side.build();
    for (int k = 0; k < n; ++k) out.emplace_back(starts[static_cast<std::size_t>(k)], std::move(meshes[static_cast<std::size_t>(k)]));
  }
  return out;
}

/// `count` of `n` indices, which from the seed: a partial shuffle.
std::vector<int> seeded_pick(int n, int count, std::uint64_t seed, std::uint64_t stream) {
  std::vector<int> all(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) all[static_cast<std::size_t>(i)] = i;
  SplitMix rng(seed, stream);
  for (int i = 0; i < count && i < n; ++i) {
    const auto j = static_cast<std::size_t>(i) + rng.next() % static_cast<std::uint64_t>(n - i);
    std::swap(all[static_cast<std::size_t>(i)], all[j]);
  }
  all.resize(static_cast<std::size_t>(std::min(count, n)));
  std::sort(all.begin(), all.end());
  return all;
}

/// A band of ground cover along the rows of `block`: v its centre line
/// across them, `width_m` wide, the rows' length long.
void add_cover_band(XmlWriter& x, const scenes::PvArray& block, double v, double width_m, const std::string& material) {
  const double length_m = scenes::row_length_m(block);
  const Eigen::Vector2d c = scenes::array_to_world(block, length_m / 2, v);
  x.line("<geom class=\"scenery\" type=\"plane\" size=\"" + v3(length_m / 2, width_m / 2, 1) + "\" pos=\"" +
         v3(c.x(), c.y(), scenes::kGroundCoverM) + "\" euler=\"0 0 " + f(block.azimuth_deg) + "\" material=\"" +
         material + "\"/>");
}

/// Road pieces are at most this long, so that the view cull leaves out
/// those out of sight; they lie between the soil's backdrop (5 mm down) and
/// the route's tiles (at 0), which cover them near the route.
constexpr double kRoadPieceM = 48.0, kRoadPlaneZM = -0.0025;

/// A plant's service roads, gravel wherever they run: planes with the
/// first of the roads' gravel images, in pieces along each road.
void add_road_planes(XmlWriter& x, const scenes::Scenario& s) {
  if (!draws_road_planes(s)) return;
  const scenes::PvArray& base = s.pv_arrays[static_cast<std::size_t>(s.plant->first_array)];
  const std::string material = "groundt" + std::to_string(s.ground.soil_images);
  int k = 0;
  for (const Eigen::Vector4d& r : s.plant->roads_uv) {
    const bool along_u = r[2] - r[0] >= r[3] - r[1];
    const double length = along_u ? r[2] - r[0] : r[3] - r[1];
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / kRoadPieceM - 1e-9)));
    const double step = length / pieces;
    for (int i = 0; i < pieces; ++i) {
      const double u0 = along_u ? r[0] + i * step : r[0], u1 = along_u ? u0 + step : r[2];
      const double v0 = along_u ? r[1] : r[1] + i * step, v1 = along_u ? r[3] : v0 + step;
      const Eigen::Vector2d c = scenes::array_to_world(base, 0.5 * (u0 + u1), 0.5 * (v0 + v1));
      x.line("<geom name=\"" + std::string(kRoadPlanePrefix) + std::to_string(k++) +
             "\" class=\"scenery\" type=\"plane\" size=\"" + v3((u1 - u0) / 2, (v1 - v0) / 2, 1) +
             "\" pos=\"" + v3(c.x(), c.y(), kRoadPlaneZM) + "\" euler=\"0 0 " + f(base.azimuth_deg) +
             "\" material=\"" + material + "\"/>");
    }
  }
}

/// Tyre tracks in a share of each block's aisles, grass under a share of
/// its rows, which ones from the station's seed.
void add_ground_cover(XmlWriter& x, const scenes::Scenario& s) {
  const scenes::PlantSummary& plant = *s.plant;
  for (int b = 0; b < plant.blocks; ++b) {
    const scenes::PvArray& block = s.pv_arrays[static_cast<std::size_t>(plant.first_array + b)];
    const double pitch = block.row_pitch_m, footprint = scenes::row_footprint_m(block);
    const auto seed = s.station_seed_or_seed();
    for (const int k : seeded_pick(block.rows + 1, plant.tracked_aisles, seed, 0x7AC40000ULL + static_cast<std::uint64_t>(b)))
      for (const double side : {-1.0, 1.0})
        add_cover_band(x, block, k * pitch - (pitch - footprint) / 2 + side * scenes::kTrackGaugeM / 2,
                       scenes::kTrackWidthM, "groundtrack");
    for (const int row : seeded_pick(block.rows, plant.grass_rows, seed, 0x6A550000ULL + static_cast<std::uint64_t>(b)))
      add_cover_band(x, block, row * pitch + footprint / 2, scenes::kGrassStripShare * footprint, "groundgrass");
  }
}

const char* finish_material(scenes::FixtureFinish f) {
  switch (f) {
    case scenes::FixtureFinish::kSteel: return "steel";
    case scenes::FixtureFinish::kEnclosure: return "enclosure";
    case scenes::FixtureFinish::kPlaster: return "plaster";
  }
  return "steel";
}

/// A row sign's plate as a mesh: the plate's centre at the origin, its
/// front facing +x, its width along y, the label's cell of the atlas on the
/// front and on the back, each read the right way round from its side.
std::string sign_plate_mesh_line(const std::string& name, int label, int labels) {
  const int lines = std::max(1, (labels + kSignAtlasColumns - 1) / kSignAtlasColumns);
  const double u0 = static_cast<double>(label % kSignAtlasColumns) / kSignAtlasColumns,
               u1 = u0 + 1.0 / kSignAtlasColumns;
  // MuJoCo's texture coordinate v runs from the image's first row down.
  const double v_top = static_cast<double>(label / kSignAtlasColumns) / lines, v_bottom = v_top + 1.0 / lines;
  const double t = scenes::kRowSignPlateThickM / 2, w = scenes::kRowSignPlateWideM / 2,
               h = scenes::kRowSignPlateHighM / 2;
  // Front (x = +t; the viewer's right is +y), then back (x = -t; right is -y):
  // bottom left, bottom right, top right, top left as each viewer sees them.
  const std::array<Eigen::Vector3d, 8> vertices = {
      Eigen::Vector3d(t, -w, -h), Eigen::Vector3d(t, w, -h),   Eigen::Vector3d(t, w, h),   Eigen::Vector3d(t, -w, h),
      Eigen::Vector3d(-t, w, -h), Eigen::Vector3d(-t, -w, -h), Eigen::Vector3d(-t, -w, h), Eigen::Vector3d(-t, w, h)};
  const std::array<std::array<double, 2>, 4> corners = {{{u0, v_bottom}, {u1, v_bottom}, {u1, v_top}, {u0, v_top}}};
  std::string v, tc;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    v += (i ? "  " : "") + v3(vertices[i]);
    tc += (i ? "  " : "") + f(corners[i % 4][0]) + " " + f(corners[i % 4][1]);
  }
  // Both faces, then the edges: bottom, right of the front, top, left of the front.
  const char* faces = "0 1 2  0 2 3  4 5 6  4 6 7  0 5 4  0 4 1  1 4 7  1 7 2  2 7 6  2 6 3  3 6 5  3 5 0";
  return "<mesh name=\"" + name + "\" vertex=\"" + v + "\" texcoord=\"" + tc + "\" face=\"" + faces + "\"/>";
}

std::string mesh_line(const std::string& name, const FenceMesh& m) {
  std::string v, fc;
  v.reserve(m.vertices.size() * 24);
  for (const Eigen::Vector3d& p : m.vertices) v += (v.empty() ? "" : "  ") + v3(p);
  for (const auto& t : m.faces)
    fc += (fc.empty() ? "" : "  ") + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " + std::to_string(t[2]);
  return "<mesh name=\"" + name + "\" vertex=\"" + v + "\" face=\"" + fc + "\"/>";
}

}  // namespace

void add_plant_assets(XmlWriter& x, const scenes::Scenario& s, const scenes::GroundRelief& ground) {
  if (!s.plant) return;
  // A combiner box's or the dock's light grey polyester; galvanised chain link.
  x.line("<material name=\"enclosure\" rgba=\"0.86 0.86 0.84 1\" specular=\"0.15\" shininess=\"0.2\"/>");
  x.line("<material name=\"fence\" rgba=\"0.66 0.68 0.70 1\" specular=\"0.3\" shininess=\"0.3\"/>");
  // Ground cover: named "ground..." so that it is the ground's surface.
  for (const auto& [count, name] : {std::pair{s.plant->tracked_aisles, "track"}, {s.plant->grass_rows, "grass"}})
    if (count > 0)
      x.line(std::string("<material name=\"ground") + name + "\" texture=\"" + name + "\" texuniform=\"true\" texrepeat=\"" +
             f(1.0 / kCoverTileM) + " " + f(1.0 / kCoverTileM) + "\" specular=\"0.02\" shininess=\"0.05\"/>");
  if (!s.plant->row_signs.empty()) {
    x.line("<material name=\"rowsign\" texture=\"rowsigns\" specular=\"0.2\" shininess=\"0.3\"/>");
    const int labels = static_cast<int>(s.plant->sign_labels.size());
    for (std::size_t k = 0; k < s.plant->row_signs.size(); ++k)
      x.line(sign_plate_mesh_line("sign" + std::to_string(k), s.plant->row_signs[k].label, labels));
  }
  if (!s.plant->fence) return;
  const auto meshes = fence_meshes(*s.plant->fence, ground);
  for (std::size_t k = 0; k < meshes.size(); ++k)
    if (!meshes[k].second.faces.empty()) x.line(mesh_line("fence" + std::to_string(k), meshes[k].second));
}

bool draws_road_planes(const scenes::Scenario& s) {
  return s.plant && !s.plant->roads_uv.empty() && !s.ground.relief && s.ground.soil_images > 0 &&
         s.ground.drawn_tiling() == scenes::GroundTiling::kVaried;
}

void add_plant_fixtures(XmlWriter& x, const scenes::Scenario& s, const scenes::GroundRelief& ground) {
  if (!s.plant) return;
  const scenes::PlantSummary& plant = *s.plant;
  if (plant.fence) {
    const auto meshes = fence_meshes(*plant.fence, ground);
    for (std::size_t k = 0; k < meshes.size(); ++k) {
      if (meshes[k].second.faces.empty()) continue;
      const Eigen::Vector2d& p = meshes[k].first;
      x.line("<geom name=\"fence" + std::to_string(k) + "\" class=\"scenery\" type=\"mesh\" mesh=\"fence" +
             std::to_string(k) + "\" pos=\"" + v3(p.x(), p.y(), 0) + "\" material=\"fence\"/>");
    }
  }
  add_road_planes(x, s);
  add_ground_cover(x, s);
  for (std::size_t k = 0; k < plant.row_signs.size(); ++k) {
    const scenes::RowSign& r = plant.row_signs[k];
    const double yaw = r.yaw_deg * M_PI / 180.0, z0 = ground.height_m(r.centre_m);
    const double foot = ground.flat() ? 0.0 : kIntoReliefM;
    x.line("<geom name=\"signpost" + std::to_string(k) + "\" class=\"scenery\" type=\"box\" size=\"" +
           v3(scenes::kRowSignPostM / 2, scenes::kRowSignPostM / 2, (scenes::kRowSignPostHighM + foot) / 2) +
           "\" pos=\"" + v3(r.centre_m.x(), r.centre_m.y(), z0 + (scenes::kRowSignPostHighM - foot) / 2) +
           "\" euler=\"0 0 " + f(r.yaw_deg) + "\" material=\"steel\"/>");
    // The plate on the post's front face.
    const double out_m = scenes::kRowSignPostM / 2 + scenes::kRowSignPlateThickM / 2;
    const Eigen::Vector3d c(r.centre_m.x() + out_m * std::cos(yaw), r.centre_m.y() + out_m * std::sin(yaw),
                            z0 + scenes::kRowSignPlateBaseM + scenes::kRowSignPlateHighM / 2);
    x.line("<geom name=\"sign" + std::to_string(k) + "\" class=\"scenery\" type=\"mesh\" mesh=\"sign" +
           std::to_string(k) + "\" pos=\"" + v3(c) + "\" euler=\"0 0 " + f(r.yaw_deg) + "\" material=\"rowsign\"/>");
  }
  for (std::size_t i = 0; i < plant.fixtures.size(); ++i) {
    const scenes::Fixture& fx = plant.fixtures[i];
    const double z0 = ground.height_m(fx.centre_m) + fx.base_m;
    const double foot = fx.base_m == 0 && !ground.flat() ? kIntoReliefM : 0.0;
    x.line("<geom name=\"fixture" + std::to_string(i) + "\" class=\"scenery\" type=\"box\" size=\"" +
           v3(fx.size_m.x() / 2, fx.size_m.y() / 2, (fx.size_m.z() + foot) / 2) + "\" pos=\"" +
           v3(fx.centre_m.x(), fx.centre_m.y(), z0 + (fx.size_m.z() - foot) / 2) + "\" euler=\"0 0 " + f(fx.yaw_deg) +
           "\" material=\"" + finish_material(fx.finish) + "\"/>");
  }
}

}  // namespace pvb::sim::mjcf
