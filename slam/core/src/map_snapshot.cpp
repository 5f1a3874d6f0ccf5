#include "pvb/slam/core/map_snapshot.hpp"

#include <Eigen/Geometry>
#include <iomanip>
#include <istream>
#include <map>
#include <ostream>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/slam/core/map.hpp"

namespace pvb::slam {

MapSnapshot snapshot_map(const Map& map, const StereoIntrinsics& K, double scale_factor) {
  MapSnapshot s;
  s.K = K;
  s.scale_factor = scale_factor;
  std::map<std::uint64_t, std::size_t> kf_index;
  for (const auto& [id, kf] : map.keyframes()) {
    if (kf->bad() || map.map_of(*kf) != 0) continue;  // a provisional map lies in a frame of its own
    kf_index[id] = s.keyframes.size();
    s.keyframes.push_back({id, kf->t_ns(), kf->T_c_w()});
  }
  for (const auto& [id, mp] : map.points()) {
    if (mp->bad()) continue;
    const std::size_t p = s.points.size();
    const auto ref = mp->reference_keyframe();
    bool any = false;
    for (const auto& [kf_id, o] : mp->observations()) {
      const auto it = kf_index.find(kf_id);
      const auto kf = o.kf.lock();
      if (it == kf_index.end() || !kf) continue;
      const Frame& f = kf->frame();
      const Observation obs = f.observation(o.idx);
      s.measurements.push_back({it->second, p, obs.uv, obs.u_right, f.keys_un[o.idx].octave});
      any = true;
    }
    if (any) s.points.push_back({id, mp->p_w(), ref ? ref->id() : 0});
  }
  return s;
}

void write_map_snapshot(const MapSnapshot& s, std::ostream& os, const std::string& name) {
  os << "# PE-SLAM map snapshot (map_snapshot.hpp): K fx fy cx cy bf scale_factor; F id t_ns qx qy qz qw tx ty tz "
        "(T_c_w); P id x y z ref_kf; O kf_index point_index u v u_right octave\n";
  os << std::setprecision(17);
  os << "K " << s.K.fx << ' ' << s.K.fy << ' ' << s.K.cx << ' ' << s.K.cy << ' ' << s.K.bf << ' ' << s.scale_factor
     << '\n';
  for (const auto& k : s.keyframes) {
    const Eigen::Quaterniond q(k.T_c_w.linear());
    const Eigen::Vector3d& t = k.T_c_w.translation();
    os << "F " << k.id << ' ' << k.t_ns << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << ' ' << t.x()
       << ' ' << t.y() << ' ' << t.z() << '\n';
  }
  for (const auto& p : s.points)
    os << "P " << p.id << ' ' << p.p_w.x() << ' ' << p.p_w.y() << ' ' << p.p_w.z() << ' ' << p.reference_keyframe_id
       << '\n';
  for (const auto& m : s.measurements)
    os << "O " << m.keyframe << ' ' << m.point << ' ' << m.uv.x() << ' ' << m.uv.y() << ' ' << m.u_right << ' '
       << m.octave << '\n';
  os.flush();
  if (!os) throw IoError(name, "cannot write the map snapshot");
}

MapSnapshot read_map_snapshot(std::istream& is, const std::string& name) {
  MapSnapshot s;
  bool have_k = false;
  std::string line;
  int line_no = 0;
  // Measurements are checked against the point count at the end: points
  // may follow them in a hand-made file.
  std::vector<int> measurement_lines;
  while (std::getline(is, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    const auto bad = [&](const std::string& expected) { throw IoError(name, "expected " + expected, line_no); };
    if (tag == "K") {
      if (!(ls >> s.K.fx >> s.K.fy >> s.K.cx >> s.K.cy >> s.K.bf >> s.scale_factor)) bad("K fx fy cx cy bf scale_factor");
      if (!(s.K.fx > 0 && s.K.fy > 0 && s.scale_factor > 1)) bad("fx, fy > 0 and scale_factor > 1");
      have_k = true;
    } else if (tag == "F") {
      MapSnapshot::Keyframe k;
      double q[4], t[3];
      if (!(ls >> k.id >> k.t_ns >> q[0] >> q[1] >> q[2] >> q[3] >> t[0] >> t[1] >> t[2]))
        bad("F id t_ns qx qy qz qw tx ty tz");
      const Eigen::Quaterniond quat(q[3], q[0], q[1], q[2]);
      if (!(std::abs(quat.norm() - 1.0) < 1e-6)) bad("a unit quaternion");
      k.T_c_w = geom::make_se3(quat, Eigen::Vector3d(t[0], t[1], t[2]));
      s.keyframes.push_back(k);
    } else if (tag == "P") {
      MapSnapshot::Point p;
      if (!(ls >> p.id >> p.p_w.x() >> p.p_w.y() >> p.p_w.z() >> p.reference_keyframe_id))
        bad("P id x y z reference_keyframe_id");
      s.points.push_back(p);
    } else if (tag == "O") {
      MapSnapshot::Measurement m;
      if (!(ls >> m.keyframe >> m.point >> m.uv.x() >> m.uv.y() >> m.u_right >> m.octave))
        bad("O keyframe_index point_index u v u_right octave");
      if (m.octave < 0) bad("octave >= 0");
      s.measurements.push_back(m);
      measurement_lines.push_back(line_no);
    } else {
      bad("a record K, F, P or O, got '" + tag + "'");
    }
    std::string extra;
    if (ls >> extra) bad("end of line after the " + tag + " record, got '" + extra + "'");
  }
  if (is.bad()) throw IoError(name, "read failed");
  if (!have_k) throw IoError(name, "no K record (intrinsics)");
  for (std::size_t i = 0; i < s.measurements.size(); ++i) {
    const auto& m = s.measurements[i];
    if (m.keyframe >= s.keyframes.size())
      throw IoError(name, "keyframe index " + std::to_string(m.keyframe) + " out of range (" +
                              std::to_string(s.keyframes.size()) + " F records)", measurement_lines[i]);
    if (m.point >= s.points.size())
      throw IoError(name, "point index " + std::to_string(m.point) + " out of range (" +
                              std::to_string(s.points.size()) + " P records)", measurement_lines[i]);
  }
  return s;
}

}  // namespace pvb::slam
