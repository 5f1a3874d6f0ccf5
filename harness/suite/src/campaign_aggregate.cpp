#include "pvb/suite/campaign_aggregate.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <map>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::suite {
namespace {

std::optional<double> number_at(const YAML::Node& n) {
  double v = 0;
  if (!n.IsDefined() || !n.IsScalar() || n.Tag() == "!" || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
    return std::nullopt;
  return v;
}

std::string text_at(const YAML::Node& n) { return n.IsDefined() && n.IsScalar() ? n.Scalar() : ""; }

CampaignSessionMetrics read_session(const YAML::Node& s) {
  CampaignSessionMetrics m;
  m.name = text_at(s["name"]);
  m.mode = text_at(s["mode"]);
  m.map = s["map"].IsNull() ? "" : text_at(s["map"]);
  m.status = s["status"].IsNull() ? "" : text_at(s["status"]);
  m.error = s["error"].IsNull() ? "" : text_at(s["error"]);
  m.frames = static_cast<int>(number_at(s["frames"]).value_or(0));
  m.lost_frames = static_cast<int>(number_at(s["lost_frames"]).value_or(0));
  m.keyframes = static_cast<int>(number_at(s["keyframes"]).value_or(0));
  m.keyframes_loaded = static_cast<int>(number_at(s["keyframes_loaded"]).value_or(0));
  m.tracking_ms_median = number_at(s["tracking_ms_median"]).value_or(0);
  const YAML::Node l = s["map_report"].IsMap() ? s["map_report"]["localisation"] : YAML::Node();
  if (l.IsDefined() && l.IsMap()) {
    m.share_fine = number_at(l["within"]["fine"]["share"]);
    m.share_high = number_at(l["within"]["high"]["share"]);
    if (const auto w = number_at(l["wrong_place"])) m.wrong_place = static_cast<int>(*w);
    if (const auto f = number_at(l["first_pose_frame"])) m.first_pose_frame = static_cast<int>(*f);
  }
  return m;
}

/// Half-width of the 95 % interval of the mean (Student's t).
double ci95(const Summary& s) {
  return s.count > 1 ? student_t_quantile(0.975, s.count - 1) * s.sd / std::sqrt(double(s.count)) : 0.0;
}

std::string pct(const Summary& s, double ci) {
  if (s.count == 0) return "-";
  return format_fixed(100 * s.mean, 1) + " ± " + format_fixed(100 * ci, 1) + " % (min " +
         format_fixed(100 * s.min, 1) + " %)";
}

std::string summary_json(const Summary& s) {
  return "{\"count\": " + std::to_string(s.count) + ", \"mean\": " + json_number(s.mean) +
         ", \"sd\": " + json_number(s.sd) + ", \"min\": " + json_number(s.min) + ", \"max\": " + json_number(s.max) + "}";
}

}  // namespace

CampaignSeed read_campaign_seed(std::uint64_t seed, const std::string& path) {
  CampaignSeed c;
  c.seed = seed;
  try {
    const YAML::Node root = YAML::LoadFile(path);
    c.campaign = text_at(root["campaign"]);
    const YAML::Node sessions = root["sessions"];
    if (!sessions.IsSequence()) throw IoError(path, "no sessions list");
    for (const auto& s : sessions) c.sessions.push_back(read_session(s));
  } catch (const YAML::Exception& e) {
    c.error = path + ": " + e.what();
  } catch (const Error& e) {
    c.error = e.what();
  }
  return c;
}

CampaignAggregate aggregate_campaign(const std::vector<CampaignSeed>& seeds) {
  CampaignAggregate a;
  std::vector<std::string> order;
  std::map<std::string, std::vector<const CampaignSessionMetrics*>> by_name;
  for (const CampaignSeed& s : seeds) {
    a.seeds.push_back(s.seed);
    if (!s.error.empty()) a.seed_errors.push_back("seed " + std::to_string(s.seed) + ": " + s.error);
    if (a.campaign.empty()) a.campaign = s.campaign;
    for (const auto& m : s.sessions) {
      if (!by_name.count(m.name)) order.push_back(m.name);
      by_name[m.name].push_back(&m);
    }
  }
  for (const std::string& name : order) {
    CampaignSessionAggregate g;
    std::vector<double> fine, high, first, added, ms;
    for (const CampaignSessionMetrics* m : by_name[name]) {
      g.name = m->name, g.mode = m->mode, g.map = m->map;
      ++g.seeds;
      if (m->status != "completed") ++g.failed;
      if (m->share_fine) fine.push_back(*m->share_fine);
      if (m->share_high) high.push_back(*m->share_high);
      g.wrong_place += m->wrong_place.value_or(0);
      if (m->first_pose_frame) first.push_back(*m->first_pose_frame);
      else if (m->share_fine) ++g.never_posed;
      if (m->status == "completed") added.push_back(m->keyframes - m->keyframes_loaded);
      ms.push_back(m->tracking_ms_median);
    }
    g.fine = summarize(fine), g.high = summarize(high), g.first_pose_frame = summarize(first);
    g.keyframes_added = summarize(added), g.tracking_ms_median = summarize(ms);
    g.fine_ci95 = ci95(g.fine), g.high_ci95 = ci95(g.high);
    a.sessions.push_back(g);
  }
  return a;
}

std::string format_campaign_markdown(const CampaignAggregate& a) {
  std::string out = "# Campaign " + a.campaign + " over " + std::to_string(a.seeds.size()) + " seeds\n\n";
  out += "| session | mode | map | seeds (failed) | within 0.05 m/1 deg | within 0.25 m/2 deg | wrong place (all seeds) "
         "| first pose frame (median of mean, max) | keyframes added (mean) | tracking ms median (mean) |\n";
  out += "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& g : a.sessions) {
    const std::string first = g.first_pose_frame.count
                                  ? format_fixed(g.first_pose_frame.mean, 1) + ", max " +
                                        format_fixed(g.first_pose_frame.max, 0)
                                  : "-";
    out += "| " + g.name + " | " + g.mode + " | " + (g.map.empty() ? "-" : g.map) + " | " +
           std::to_string(g.seeds) + " (" + std::to_string(g.failed) + ") | " + pct(g.fine, g.fine_ci95) + " | " +
           pct(g.high, g.high_ci95) + " | " + (g.fine.count ? std::to_string(g.wrong_place) : "-") + " | " + first +
           (g.never_posed ? " (" + std::to_string(g.never_posed) + " never)" : "") + " | " +
           format_fixed(g.keyframes_added.mean, 1) + " | " + format_fixed(g.tracking_ms_median.mean, 2) + " |\n";
  }
  out += "\nIntervals: 95 % of the mean over seeds (Student's t); min: the worst seed.\n";
  for (const auto& e : a.seed_errors) out += "\n- " + e;
  return out + "\n";
}

std::string format_campaign_json(const CampaignAggregate& a) {
  std::string out = "{\n  \"campaign\": \"" + json_escape(a.campaign) + "\",\n  \"seeds\": [";
  for (std::size_t i = 0; i < a.seeds.size(); ++i) out += (i ? ", " : "") + std::to_string(a.seeds[i]);
  out += "],\n  \"sessions\": [";
  for (std::size_t i = 0; i < a.sessions.size(); ++i) {
    const auto& g = a.sessions[i];
    out += std::string(i ? "," : "") + "\n    {\"name\": \"" + json_escape(g.name) + "\", \"mode\": \"" + g.mode +
           "\", \"seeds\": " + std::to_string(g.seeds) + ", \"failed\": " + std::to_string(g.failed) +
           ", \"fine\": " + summary_json(g.fine) + ", \"fine_ci95\": " + json_number(g.fine_ci95) +
           ", \"high\": " + summary_json(g.high) + ", \"high_ci95\": " + json_number(g.high_ci95) +
           ", \"wrong_place\": " + std::to_string(g.wrong_place) + ", \"first_pose_frame\": " +
           summary_json(g.first_pose_frame) + ", \"never_posed\": " + std::to_string(g.never_posed) +
           ", \"keyframes_added\": " + summary_json(g.keyframes_added) + "}";
  }
  return out + "\n  ]\n}\n";
}

}  // namespace pvb::suite
