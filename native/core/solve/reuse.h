// What a relight may change (SolveReuse, solve.h): the lighting, not the
// geometry or the options the links were made with, and only to values the
// links already carry.
#pragma once

#include <string>

#include "radiosity/scene.h"
#include "radiosity/solve.h"

namespace radiosity {

// Why `scene` solved with `options` cannot reuse the elements and links made
// for `kept` with `kept_options` (None if it can). Allowed to differ: the
// sides' emission and reflectance, where what emits or reflects is a subset
// of what did (links are made only from surfaces that emit or reflect to
// surfaces that reflect, and only where light reaches), and the colours of
// the lights (one turned off or on is left out of or added to the scene:
// refused); and the limits (time, elements, memory, threads, priority,
// tolerance, iterations).
RelightRefusal relight_refusal(const Scene& kept, const SolveOptions& kept_options,
                               const Scene& scene, const SolveOptions& options);

// About how much brighter `scene`'s lighting is than `kept`'s: the ratio of
// their emitted power plus the lights' luminances, exact when every emitter and
// light changed by the same factor; 1 when either has none.
double lighting_scale(const Scene& kept, const Scene& scene);

// Copies `scene`'s lighting (emission, reflectance, light colours and the
// emitted power) into `kept`, which has the same geometry (relight_refusal).
void take_lighting(Scene& kept, const Scene& scene);

}  // namespace radiosity
