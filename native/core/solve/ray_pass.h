// A first look at the light before any link exists (issue 32): a solution that
// costs rays per face, not pairs of faces, so that a solve stopped while it
// links (its time or memory budget, or Esc) still returns the scene lit right
// in brightness, coarsely, instead of black.
//
// Every top-level element that reflects takes points at random on itself, and
// from each:
// - the direct light of the emitting sides, both by a point drawn on an
//   emitter (in proportion to its power, with a shadow ray) and by a cosine-
//   weighted ray that meets one, weighted by the power heuristic (Veach 1997),
//   so that neither the 1 / d^2 near an emitter's edge nor a small bright lamp
//   seen by few rays makes it noisy;
// - the direct light of point, spot and sun lights (one shadow ray each, a
//   point or spot taken as a point), and the sky where the ray leaves the scene;
// - the top-level element the cosine ray meets first (the side it meets, by
//   the hit face's normal), remembered.
// Then the reflected radiance is iterated as Jacobi to convergence, each
// element gathering the mean over its rays of what they met: ray-traced form
// factors (Sbert's local lines, 1993; stochastic Jacobi radiosity, Bekaert
// 1999). Unbiased in expectation, so its brightness is right; each element's
// light is a mean of a few dozen rays in a large scene, so it is blotchy and
// constant over the element.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/visibility/ray_scene.h"
#include "radiosity/color.h"

namespace radiosity {

struct RayPass {
  // Per top-level element (they are the first elements): what it gathers (H)
  // from emitters, lights, sky and reflecting surfaces, uniform over it.
  std::vector<Rgb> gathered;
  // Per top-level element that reflects: the share of its cosine rays that
  // met no side of a patch that has an element (they left for the sky or met
  // the back of a one-sided face): 0 where the surroundings close around it
  // (energy_balance.h).
  std::vector<float> escaped;
  // Per top-level element: 1 where the side reflects and no light reaches it
  // by the pass's rays (the inside of a closed object with nothing lit in
  // it, the outside of a closed room under no sky). Light starts at the
  // emitting sides and the sides an emitter, a light or the sky lit directly,
  // and goes from a side to every side whose rays met it. Such sides are left
  // out of linking: their links would carry nothing
  // (Solver::drop_links_light_cannot_reach drops them after linking), yet
  // the insides of a dense closed mesh face each other at every distance.
  std::vector<std::uint8_t> unlit;
  // Per reflecting top-level element, its `rays` cosine rays: the top-level
  // element each met first (kNone: the sky, or the back of a one-sided face),
  // at met[element * rays + k]; and how many of its rays brought direct light
  // (an emitter's, a light's or the sky's). What dim_sides.h reads.
  std::vector<std::int32_t> met;
  std::vector<std::uint32_t> lighting_rays;
  int rays = 0;        // per reflecting top-level element
  int iterations = 0;  // Jacobi iterations
  bool complete = false;
};

// Rays per element for a scene of `reflecting` top-level elements: about
// a million in all, between 32 and 2,048 each (as many shadow rays again).
int ray_pass_rays(std::size_t reflecting);

// `occluders`: what casts shadows (the lights' shadow rays). Returns
// incomplete once `cancelled` says so.
RayPass ray_pass(const Hierarchy& hierarchy, const RayScene& occluders,
                 const std::function<bool()>& cancelled);

}  // namespace radiosity
