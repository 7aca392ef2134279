// Evaluating many links at once (DESIGN s5), in parallel and deterministic:
// each link is evaluated into its own slot and the visible ones are kept in
// their original order, so the result does not depend on the thread count.
#pragma once

#include <functional>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/direct_light.h"
#include "core/solve/link_transport.h"
#include "radiosity/solve.h"

namespace radiosity {

// Evaluates `candidates` and returns those that carry light. `stop` is polled
// between chunks of about a thousand link groups; when it turns true the
// evaluation ends early and `cut_short` is set (the partial result must then
// be discarded). CPU time per part is added to `cpu`.
std::vector<Link> evaluate_links(const LinkEvaluator& evaluator, const Hierarchy& hierarchy,
                                 std::vector<Link>&& candidates, const std::function<bool()>& stop,
                                 LinkTimings& cpu, bool& cut_short);

// Evaluates light links and returns those that deliver light.
std::vector<LightLink> evaluate_light_links(const DirectLight& direct,
                                            std::vector<LightLink>&& candidates);

}  // namespace radiosity
