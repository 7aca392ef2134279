#include "core/solve/link_batch.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <span>

namespace radiosity {

// Runs of up to four links made by one split (refinement keeps them
// consecutive) are evaluated together: sibling receivers linked to one emitter
// share their common corners (CornerMemo); one receiver linked to sibling
// emitters shares the parent emitter's shaft and visible region. The runs
// depend only on the link order.
std::vector<Link> evaluate_links(const LinkEvaluator& evaluator, const Hierarchy& hierarchy,
                                 std::vector<Link>&& candidates, const std::function<bool()>& stop,
                                 LinkTimings& cpu, bool& cut_short) {
  enum class Run : std::uint8_t { Single, SiblingReceivers, SiblingEmitters };
  const auto parent = [&](std::int32_t e) { return hierarchy.element(e).parent; };
  const auto run_of = [&](const Link& a, const Link& b) {
    // Roots have no parent: they never come from one split.
    if (a.emitter == b.emitter && parent(a.receiver) != kNone &&
        parent(a.receiver) == parent(b.receiver))
      return Run::SiblingReceivers;
    if (a.receiver == b.receiver && parent(a.emitter) != kNone &&
        parent(a.emitter) == parent(b.emitter))
      return Run::SiblingEmitters;
    return Run::Single;
  };
  std::vector<std::uint32_t> group_start;
  std::vector<Run> group_kind;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Run run = i > 0 ? run_of(candidates[i - 1], candidates[i]) : Run::Single;
    const bool continues = !group_start.empty() && i - group_start.back() < 4 &&
                           run != Run::Single &&
                           (group_kind.back() == Run::Single || group_kind.back() == run);
    if (continues) {
      group_kind.back() = run;
    } else {
      group_start.push_back(static_cast<std::uint32_t>(i));
      group_kind.push_back(Run::Single);
    }
  }
  group_start.push_back(static_cast<std::uint32_t>(candidates.size()));
  const size_t groups = group_kind.size();

  std::vector<std::uint8_t> visible(candidates.size(), 0);
  tbb::enumerable_thread_specific<LinkTimings> timings;
  // Chunks keep cancellation prompt without a check per link.
  const size_t chunk = 1024;
  for (size_t begin = 0; begin < groups && !stop(); begin += chunk) {
    const size_t end = std::min(groups, begin + chunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
      LinkTimings& local = timings.local();
      for (size_t g = range.begin(); g != range.end(); ++g) {
        const size_t first = group_start[g], count = group_start[g + 1] - first;
        if (group_kind[g] == Run::SiblingEmitters) {
          evaluator.evaluate_emitter_siblings(
              std::span<Link>(candidates.data() + first, count), local,
              std::span<std::uint8_t>(visible.data() + first, count));
          continue;
        }
        CornerMemo memo;
        for (size_t i = first; i < first + count; ++i) {
          visible[i] = evaluator.evaluate(candidates[i], local, &memo) ? 1 : 0;
        }
      }
    });
  }
  for (const LinkTimings& t : timings) cpu += t;
  cut_short = groups > 0 && stop();
  size_t kept = 0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (visible[i]) candidates[kept++] = candidates[i];
  }
  candidates.resize(kept);
  return std::move(candidates);
}

// Deterministic for any thread count, as evaluate_links.
std::vector<LightLink> evaluate_light_links(const DirectLight& direct,
                                            std::vector<LightLink>&& candidates) {
  std::vector<std::uint8_t> lit(candidates.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i)
      lit[i] = direct.evaluate(candidates[i]) ? 1 : 0;
  });
  size_t kept = 0;
  for (size_t i = 0; i < candidates.size(); ++i)
    if (lit[i]) candidates[kept++] = candidates[i];
  candidates.resize(kept);
  return std::move(candidates);
}

}  // namespace radiosity
