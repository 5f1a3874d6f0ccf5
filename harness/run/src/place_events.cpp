#include "pvb/run/place_events.hpp"

namespace pvb::run {

PlaceRecognition collect_place_recognition(const slam::System& system, std::vector<std::int64_t> keyframe_t_ns) {
  PlaceRecognition p;
  const slam::LoopClosingStats loops = system.loop_stats();
  p.loops_proposed = loops.consistent;
  p.loops_accepted = static_cast<int>(loops.loops.size());
  for (const slam::LoopEvent& e : loops.loops) p.loops.push_back({e.t_ns, e.loop_t_ns, e.T_cur_loop});
  for (const slam::LoopRefusal& r : loops.refusals)
    p.refusals.push_back(
        {{r.t_ns, r.loop_t_ns, r.T_cur_loop}, r.reason, r.verified, r.correction_m, r.drift_bound_m, std::nullopt});
  p.refusals_dropped = loops.refusals_dropped;
  for (const slam::RelocEvent& e : system.relocalisations())
    p.relocalisation_events.push_back({e.t_ns, e.keyframe_t_ns, e.T_f_kf});
  p.relocalisations = static_cast<int>(p.relocalisation_events.size());
  p.keyframe_t_ns = std::move(keyframe_t_ns);
  return p;
}

void label_place_recognition(PlaceRecognition* p, const eval::Trajectory& gt) {
  p->labels = eval::label_place_events(gt, p->loops, p->relocalisation_events, p->keyframe_t_ns, p->label_options);
  for (PlaceRecognition::Refusal& r : p->refusals)
    if (r.verified) r.label = eval::label_place_event(gt, r.event, p->label_options);
}

}  // namespace pvb::run
