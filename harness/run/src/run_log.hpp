#pragma once
// Small pieces every stage of a scenario run uses: the clock, the process
// CPU time and run.log.
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "pvb/common/clock.hpp"
#include "pvb/common/output_file.hpp"

namespace pvb::run {

using Clock = std::chrono::steady_clock;

/// CPU time of the whole process (every thread, GL workers included), seconds.
double process_cpu_s();

/// run.log, flushed line by line; also kept for index.html and echoed.
class RunLog {
 public:
  RunLog(const std::string& path, std::function<void(const std::string&)> echo);
  void line(const std::string& text);
  const std::vector<std::string>& lines() const { return lines_; }

 private:
  OutputFile file_;
  std::function<void(const std::string&)> echo_;
  std::vector<std::string> lines_;
};

}  // namespace pvb::run
