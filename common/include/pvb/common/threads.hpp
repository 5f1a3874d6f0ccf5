#pragma once
// Thread names and per-thread CPU time, for profiles of the pipelined run.
// Linux only (pthread_setname_np, /proc/self/task); elsewhere the names are
// not set and the CPU table is empty.
#include <map>
#include <string>

namespace pvb {

/// Names the calling thread (at most 15 characters are kept), so that
/// thread_cpu_ms() and tools such as top -H can tell the workers apart.
void set_thread_name(const std::string& name);

/// Sets the nice value (-20 to 19; higher yields the CPU to others) of every
/// live thread of this process named `name` (exactly, as set_thread_name
/// set it).  Linux schedules threads one by one, so the rest of the process
/// keeps its priority.  Returns how many threads it changed; 0 where that
/// is not possible (no such thread, not Linux, or a lower value without the
/// right to set it).
int set_thread_nice(const std::string& name, int nice);

/// CPU time (user + system, ms) of every live thread of this process,
/// summed by name with a trailing "-<digits>" or "<digits>" removed
/// (llvmpipe-0 and llvmpipe-1 are both "llvmpipe").  Threads that have
/// exited are not in it: take it while the threads of interest still run.
std::map<std::string, double> thread_cpu_ms();

}  // namespace pvb
