// Solving at a lower CPU priority than the rest of the process, for a solve
// that runs beside an interactive interface (Blender's window): on a machine
// with as many busy solver threads as cores, the interface thread would get
// only a share of a core, and its timers, redraws and Esc arrive late.
// Each thread that works for the solve's arena is made "nicer" (Linux: nice
// applies per thread; Windows: one level below normal; macOS: the "utility"
// quality of service) when it joins; nothing is raised back, since only
// privileged processes may raise a priority. The solver's thread pool belongs
// to the module in the shipped build (TBB linked statically and hidden).
#pragma once

#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

namespace radiosity {

class YieldPriority : public tbb::task_scheduler_observer {
 public:
  explicit YieldPriority(tbb::task_arena& arena);
  ~YieldPriority() override;
  void on_scheduler_entry(bool worker) override;
};

// The niceness the solve's threads take: enough that an interface thread at
// 0 wins the CPU whenever it wants it (weight 1024 against 335 each), while
// the solve still gets every idle cycle.
inline constexpr int kSolveNiceness = 5;

// Lowers the calling thread's priority to kSolveNiceness (if it is higher).
void lower_this_thread_priority();

}  // namespace radiosity
