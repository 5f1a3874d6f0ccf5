#include "pvb/run/loss_log.hpp"

#include <cstdio>

namespace pvb::run {

std::vector<std::string> LossLog::frame(int index, double t_s, bool lost, const std::string& reason,
                                        const std::string& kind) {
  std::vector<std::string> out;
  if (!lost) {
    if (in_loss_) {
      flush(&out);
      out.push_back(summary("tracked again at frame " + std::to_string(index)));
      in_loss_ = false;
    }
    return out;
  }
  if (!in_loss_) {  // the loss itself has its own line ("lost tracking: ...")
    in_loss_ = true;
    first_lost_ = last_lost_ = index;
    kinds_.clear();
    attempts_ = 0;
    return out;
  }
  last_lost_ = index;
  ++attempts_;
  auto it = kinds_.begin();
  while (it != kinds_.end() && it->first != kind) ++it;
  if (it == kinds_.end()) kinds_.emplace_back(kind, 1);
  else ++it->second;
  if (run_first_ >= 0 && reason == run_reason_ && index == run_last_ + 1) {
    run_last_ = index;
    run_t1_ = t_s;
    return out;
  }
  flush(&out);
  run_first_ = run_last_ = index;
  run_t0_ = run_t1_ = t_s;
  run_reason_ = reason.empty() ? "no reason given" : reason;
  return out;
}

std::vector<std::string> LossLog::finish() {
  std::vector<std::string> out;
  if (!in_loss_) return out;
  flush(&out);
  out.push_back(summary("not relocalised by the end of the run"));
  in_loss_ = false;
  return out;
}

void LossLog::flush(std::vector<std::string>* out) {
  if (run_first_ < 0) return;
  char head[160];
  if (run_first_ == run_last_)
    std::snprintf(head, sizeof head, "frame %d (t = %.3f s): %s still lost: ", run_first_, run_t0_, mode_.c_str());
  else
    std::snprintf(head, sizeof head, "frames %d-%d (t = %.3f-%.3f s): %s still lost, %d frames: ", run_first_,
                  run_last_, run_t0_, run_t1_, mode_.c_str(), run_last_ - run_first_ + 1);
  out->push_back(head + run_reason_);
  run_first_ = run_last_ = -1;
}

std::string LossLog::summary(const std::string& end) const {
  const int n = last_lost_ - first_lost_ + 1;
  std::string s = "frames " + std::to_string(first_lost_) + "-" + std::to_string(last_lost_) + ": " + mode_ +
                  " lost for " + std::to_string(n) + (n == 1 ? " frame" : " frames");
  if (attempts_ > 0) {
    s += ", " + std::to_string(attempts_) + " relocalisation " + (attempts_ == 1 ? "attempt" : "attempts") +
         " failed (";
    for (std::size_t k = 0; k < kinds_.size(); ++k)
      s += (k ? ", " : "") + std::to_string(kinds_[k].second) + " " + kinds_[k].first;
    s += ")";
  }
  return s + "; " + end;
}

}  // namespace pvb::run
