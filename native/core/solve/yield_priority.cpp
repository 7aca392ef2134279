#include "core/solve/yield_priority.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>

namespace radiosity {

void lower_this_thread_priority() {
  const auto thread = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int now = getpriority(PRIO_PROCESS, thread);
  if (errno == 0 && now < kSolveNiceness) setpriority(PRIO_PROCESS, thread, kSolveNiceness);
}

YieldPriority::YieldPriority(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) {
  observe(true);
}

YieldPriority::~YieldPriority() { observe(false); }

void YieldPriority::on_scheduler_entry(bool) { lower_this_thread_priority(); }

}  // namespace radiosity
