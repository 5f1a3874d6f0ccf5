#include "pvb/common/threads.hpp"

#include <dirent.h>
#include <pthread.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cctype>
#include <fstream>
#include <sstream>

namespace pvb {

void set_thread_name(const std::string& name) {
#ifdef __linux__
  pthread_setname_np(pthread_self(), name.substr(0, 15).c_str());
#else
  (void)name;
#endif
}

namespace {

/// The name of a thread from /proc/self/task/<tid>/comm ("" when it has exited).
std::string task_name(const std::string& task_dir) {
  std::ifstream comm(task_dir + "/comm");
  std::string name;
  std::getline(comm, name);
  return name;
}

}  // namespace

int set_thread_nice(const std::string& name, int nice) {
  int changed = 0;
#ifdef __linux__
  DIR* dir = opendir("/proc/self/task");
  if (dir == nullptr) return 0;
  while (dirent* e = readdir(dir)) {
    if (e->d_name[0] == '.') continue;
    if (task_name(std::string("/proc/self/task/") + e->d_name) != name.substr(0, 15)) continue;
    // On Linux PRIO_PROCESS with a thread id sets that thread alone.
    const auto tid = static_cast<id_t>(std::stol(e->d_name));
    if (setpriority(PRIO_PROCESS, tid, nice) == 0) ++changed;
  }
  closedir(dir);
#else
  (void)name;
  (void)nice;
#endif
  return changed;
}

std::map<std::string, double> thread_cpu_ms() {
  std::map<std::string, double> out;
#ifdef __linux__
  DIR* dir = opendir("/proc/self/task");
  if (dir == nullptr) return out;
  const double ms_per_tick = 1000.0 / static_cast<double>(sysconf(_SC_CLK_TCK));
  while (dirent* e = readdir(dir)) {
    if (e->d_name[0] == '.') continue;
    const std::string task = std::string("/proc/self/task/") + e->d_name;
    std::ifstream stat(task + "/stat");
    std::string line;
    if (!std::getline(stat, line)) continue;  // the thread has just exited
    // pid (comm) state ...: comm may hold spaces and parentheses, so split
    // at the last ')'.  utime and stime are fields 14 and 15.
    const std::size_t open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close < open) continue;
    std::string name = line.substr(open + 1, close - open - 1);
    std::istringstream rest(line.substr(close + 2));
    std::string field;
    double ticks = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i)
      if (i >= 14) ticks += std::stod(field);
    // schedstat's first field is the exact time on CPU in ns, where the kernel keeps it.
    double ms = ticks * ms_per_tick;
    std::ifstream sched(task + "/schedstat");
    double on_cpu_ns = 0;
    if (sched >> on_cpu_ns) ms = on_cpu_ns / 1e6;
    while (!name.empty() && std::isdigit(static_cast<unsigned char>(name.back()))) name.pop_back();
    if (name.size() > 1 && name.back() == '-') name.pop_back();
    out[name] += ms;
  }
  closedir(dir);
#endif
  return out;
}

}  // namespace pvb
