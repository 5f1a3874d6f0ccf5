#include "run_log.hpp"

#include <cstdio>
#include <ctime>

#include "pvb/common/error.hpp"

namespace pvb::run {

double process_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

RunLog::RunLog(const std::string& path, std::function<void(const std::string&)> echo)
    : file_(path), echo_(std::move(echo)) {}

void RunLog::line(const std::string& text) {
  file_.append(text + "\n");
  lines_.push_back(text);
  if (echo_) echo_(text);
}

}  // namespace pvb::run
