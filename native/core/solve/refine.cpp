#include "core/solve/refine.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace radiosity {
namespace {

// Emitted power over area divided by the mean radiance of the lit sides, in
// the calibration room (solver.cpp, threshold_range), measured: keeps its refinement.
constexpr double kAdaptationCalibration = 0.52;

// Light a light link's samples miss (LightLink::missed) is refined for when it
// would reach this fraction of the radiance the eye adapts to.
constexpr double kMissedLight = 0.01;

}  // namespace

// The brightness an eye adapts to, which thresholds are relative to. With
// the emitted power over the area instead, a white room (whose mean radiance
// is 1 / (1 - rho) times larger) refined as if seen ten to a hundred times
// brighter: 5.5 million links at rho = 0.9. Scaled by kAdaptationCalibration
// so that the test room the thresholds were calibrated on refines as before.
double adaptation_radiance(const Hierarchy& hierarchy) {
  double light = 0.0, area = 0.0;
  for (size_t r = 0; r < hierarchy.root_count(); ++r) {
    const std::int32_t root =
        hierarchy.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (root == kNone) continue;
    const Element& e = hierarchy.element(root);
    if (!e.has_links && !(luminance(hierarchy.emission(e)) > 0.0)) continue;
    light += e.area * luminance(e.radiance);
    area += e.area;
  }
  const double mean = area > 0.0 ? light / area : 0.0;
  return mean > 0.0 ? kAdaptationCalibration * mean : hierarchy.scene().reference_radiance();
}

std::vector<double> relative_luminance(const Hierarchy& hierarchy) {
  const double adaptation = adaptation_radiance(hierarchy);
  std::vector<double> out;
  out.reserve(hierarchy.elements().size());
  for (const Element& e : hierarchy.elements())
    out.push_back(adaptation > 0.0 ? luminance(e.radiance) / adaptation : 0.0);
  return out;
}

double relative_luminance_change(const Hierarchy& hierarchy, const std::vector<double>& before) {
  const std::vector<double> now = relative_luminance(hierarchy);
  double delta = 0.0, total = 0.0;
  for (size_t i = 0; i < now.size() && i < before.size(); ++i) {
    const double area = hierarchy.elements()[i].area;
    delta += std::abs(now[i] - before[i]) * area;
    total += now[i] * area;
  }
  return total > 0.0 ? delta / total : 0.0;
}

// Then the form factor varies over that end in ways five samples (receiver)
// or a split in four (emitter shape) cannot follow: it grows quickly towards
// a shared edge. Such links follow a split end down instead.
bool near_field(const Hierarchy& hierarchy, const Link& link, bool receiver_end) {
  const Element& p = hierarchy.element(link.receiver);
  const Element& q = hierarchy.element(link.emitter);
  const double rp = 0.5 * hierarchy.diameter(p), rq = 0.5 * hierarchy.diameter(q);
  const double gap = glm::length(hierarchy.centre(p) - hierarchy.centre(q)) - rp - rq;
  return gap < 2.0 * (receiver_end ? rp : rq);
}

namespace {

// Areas this close are the same area (rounding of the input's coordinates).
constexpr double kSameArea = 1e-9;

// A light: at least 90 % of its radiance emitted (with half, the furnace's
// emitting walls counted as lights and came out 1.0e-3 off next to their edges).
bool is_light(const Hierarchy& hierarchy, const Element& e) {
  return luminance(hierarchy.emission(e)) >= 0.9 * luminance(e.radiance);
}

// How much light the link may misplace by sending its emitter's average
// radiance (Noticeable): the receiver sees the emitter's parts unequally, so up
// to F times the difference between its brightest and darkest part. Known
// once the emitter is split; its children's radiances are the parts.
double emitter_side_error(const Hierarchy& hierarchy, const Link& link) {
  const Element& q = hierarchy.element(link.emitter);
  if (q.is_leaf()) return 0.0;
  double darkest = std::numeric_limits<double>::infinity(), brightest = 0.0;
  for (int c = 0; c < 4; ++c) {
    const double l = luminance(hierarchy.element(q.first_child + c).radiance);
    darkest = std::min(darkest, l), brightest = std::max(brightest, l);
  }
  const float f = *std::max_element(link.form_factor.begin(), link.form_factor.end());
  return luminance(hierarchy.reflectance(hierarchy.element(link.receiver))) *
         static_cast<double>(f) * (brightest - darkest);
}

}  // namespace

// Split the larger of receiver and emitter unless it is at the minimum size,
// then the other.
Split choose_split(const Hierarchy& hierarchy, const Link& link, double threshold,
                   const DecisionScale& scale, const RefineLimits& limits) {
  const Element& p = hierarchy.element(link.receiver);
  const Element& q = hierarchy.element(link.emitter);
  const double brightness = luminance(hierarchy.reflectance(p) * q.radiance);
  const bool from_light = is_light(hierarchy, q);
  if (!(brightness / scale.at(p) * link.oracle > threshold)) {
    // Noticeable: the receiver's samples show no error, but the emitter's
    // average may be the wrong radiance for this receiver (the Cornell box's
    // wall tops came out 2.7 % dark at any mesh density, sent the average of
    // the ceiling beside the light, which is lit unevenly, until that link
    // was split). A split emitter is already subdivided: this costs links,
    // not elements.
    if (scale.oracle == Oracle::Noticeable && !from_light &&
        emitter_side_error(hierarchy, link) / scale.at(p) > threshold)
      return Split::Emitter;
    return Split::None;
  }
  // Noticeable judges what the receiver's samples show. A light's
  // radiance is its uniform emission, so splitting it changes no light the
  // link carries, only how the same error is shared out among four links:
  // links from lights split their receiver first. From reflecting surfaces,
  // whose radiance varies, the larger end, as the others.
  // Equal areas (opposite walls, their children) compare to within rounding:
  // the receiver goes first, so that the choice does not turn on the last bit
  // of the input (the same scene in millimetres linked differently).
  const bool receiver_first =
      p.area >= q.area * (1.0 - kSameArea) || (scale.oracle == Oracle::Noticeable && from_light &&
                                               limits.can_split(hierarchy, link.receiver));
  const std::int32_t first = receiver_first ? link.receiver : link.emitter;
  const std::int32_t second = receiver_first ? link.emitter : link.receiver;
  if (limits.can_split(hierarchy, first)) return receiver_first ? Split::Receiver : Split::Emitter;
  if (limits.can_split(hierarchy, second)) return receiver_first ? Split::Emitter : Split::Receiver;
  return Split::None;
}

std::vector<Split> choose_splits(const Hierarchy& hierarchy, std::span<const Link> links,
                                 double threshold, const DecisionScale& scale,
                                 const RefineLimits& limits) {
  std::vector<Split> decision(links.size(), Split::None);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, links.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i)
      decision[i] = choose_split(hierarchy, links[i], threshold, scale, limits);
  });
  return decision;
}

SplitLinks split_links(Hierarchy& hierarchy, std::span<const Link> links,
                       std::span<const Split> decision, const RefineLimits& limits) {
  SplitLinks out;
  for (size_t i = 0; i < links.size(); ++i) {
    const Link& link = links[i];
    if (decision[i] != Split::None) {
      const std::int32_t target = decision[i] == Split::Receiver ? link.receiver : link.emitter;
      const bool split_already = !hierarchy.element(target).is_leaf();
      if (!split_already && limits.budget_full(hierarchy)) {
        out.budget_hit = true;
      } else {
        const std::int32_t child = hierarchy.subdivide(target);
        for (std::int32_t c = child; c < child + 4; ++c) {
          Link l;
          l.receiver = decision[i] == Split::Receiver ? c : link.receiver;
          l.emitter = decision[i] == Split::Emitter ? c : link.emitter;
          out.fresh.push_back(l);
        }
        continue;
      }
    }
    out.kept.push_back(link);
  }
  return out;
}

// "near": near-field links of a split receiver; "all": all of them, and
// near-field links from a split emitter to its children too, so that they
// send what each part of the emitter reflects.
void hand_down_links(const Hierarchy& hierarchy, SolveOptions::LeafLinks leaf_links,
                     SplitLinks& links) {
  if (leaf_links == SolveOptions::LeafLinks::None) return;
  const bool all = leaf_links == SolveOptions::LeafLinks::All;
  enum Down : std::uint8_t { Stays, ToReceiverChildren, ToEmitterChildren };
  const auto hand_down = [&](const std::vector<Link>& from, std::vector<Link>& staying,
                             std::vector<Link>& moved) {
    // Decided in parallel (the distances are most of the work), applied in order.
    std::vector<Down> down(from.size(), Stays);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, from.size()), [&](const auto& range) {
      for (size_t i = range.begin(); i != range.end(); ++i) {
        const Link& link = from[i];
        if (!hierarchy.element(link.receiver).is_leaf() &&
            (all || near_field(hierarchy, link, true)))
          down[i] = ToReceiverChildren;
        else if (all && !hierarchy.element(link.emitter).is_leaf() &&
                 near_field(hierarchy, link, false))
          down[i] = ToEmitterChildren;
      }
    });
    for (size_t i = 0; i < from.size(); ++i) {
      const Link& link = from[i];
      const Element& receiver = hierarchy.element(link.receiver);
      const Element& emitter = hierarchy.element(link.emitter);
      const bool receiver_down = down[i] == ToReceiverChildren;
      if (down[i] == Stays) {
        staying.push_back(link);
        continue;
      }
      const std::int32_t first = receiver_down ? receiver.first_child : emitter.first_child;
      for (std::int32_t c = first; c < first + 4; ++c) {
        Link l;
        l.receiver = receiver_down ? c : link.receiver;
        l.emitter = receiver_down ? link.emitter : c;
        moved.push_back(l);
      }
    }
  };
  std::vector<Link> staying, fresh;
  hand_down(links.kept, staying, links.fresh);
  // A fresh link handed down stays fresh: its children go to the same list.
  hand_down(links.fresh, fresh, fresh);
  links.kept = std::move(staying);
  links.fresh = std::move(fresh);
}

// Light links take part in refinement like links whose emitter cannot be
// split: one above the threshold splits its receiver.
bool split_light_receivers(Hierarchy& hierarchy, std::span<const Light> lights,
                           std::span<const LightLink> links, double threshold,
                           const DecisionScale& scale, const RefineLimits& limits) {
  std::vector<std::uint8_t> split(links.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, links.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const LightLink& l = links[i];
      const Element& p = hierarchy.element(l.receiver);
      const double brightness = luminance(hierarchy.reflectance(p) * lights[l.light].colour);
      // Light the samples miss splits the receiver when it would show (a
      // hundredth of the adaptation level) whatever the oracle: the oracle
      // can only judge what the samples see.
      const bool missed = brightness * l.missed > kMissedLight * scale.adaptation;
      split[i] = p.is_leaf() && (missed || brightness / scale.at(p) * l.oracle > threshold) &&
                 limits.can_split(hierarchy, l.receiver);
    }
  });
  for (size_t i = 0; i < links.size(); ++i) {
    if (!split[i] || !hierarchy.element(links[i].receiver).is_leaf()) continue;
    if (limits.budget_full(hierarchy)) return true;
    hierarchy.subdivide(links[i].receiver);
  }
  return false;
}

// Direct light is always evaluated at the leaves that gather it.
std::vector<LightLink> hand_down_light_links(const Hierarchy& hierarchy,
                                             std::vector<LightLink>& links) {
  std::vector<LightLink> kept, fresh;
  for (const LightLink& l : links) {
    const Element& p = hierarchy.element(l.receiver);
    if (p.is_leaf()) {
      kept.push_back(l);
      continue;
    }
    for (std::int32_t c = p.first_child; c < p.first_child + 4; ++c) {
      LightLink child;
      child.receiver = c;
      child.light = l.light;
      fresh.push_back(child);
    }
  }
  links = std::move(kept);
  return fresh;
}

}  // namespace radiosity
