#include "core/solve/yield_priority.h"

#if defined(_WIN32)
#include <windows.h>
#elif defined(__APPLE__)
#include <pthread.h>
#include <pthread/qos.h>
#else
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#endif

namespace radiosity {

void lower_this_thread_priority() {
#if defined(_WIN32)
  // Windows has no niceness: one step below normal, the priority class's
  // nearest lower level, which the interface thread (normal) always beats.
  const HANDLE thread = GetCurrentThread();
  const int now = GetThreadPriority(thread);
  if (now != THREAD_PRIORITY_ERROR_RETURN && now > THREAD_PRIORITY_BELOW_NORMAL)
    SetThreadPriority(thread, THREAD_PRIORITY_BELOW_NORMAL);
#elif defined(__APPLE__)
  // macOS schedules threads by quality of service: "utility", Apple's class for
  // long computations whose progress the user watches, below the interface's.
  qos_class_t now = QOS_CLASS_UNSPECIFIED;
  int relative = 0;
  if (pthread_get_qos_class_np(pthread_self(), &now, &relative) == 0 &&
      (now == QOS_CLASS_UNSPECIFIED || now > QOS_CLASS_UTILITY))
    pthread_set_qos_class_self_np(QOS_CLASS_UTILITY, 0);
#else
  const auto thread = static_cast<id_t>(syscall(SYS_gettid));
  errno = 0;
  const int now = getpriority(PRIO_PROCESS, thread);
  if (errno == 0 && now < kSolveNiceness) setpriority(PRIO_PROCESS, thread, kSolveNiceness);
#endif
}

YieldPriority::YieldPriority(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) {
  observe(true);
}

YieldPriority::~YieldPriority() { observe(false); }

void YieldPriority::on_scheduler_entry(bool) { lower_this_thread_priority(); }

}  // namespace radiosity
