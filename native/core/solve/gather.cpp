#include "core/solve/gather.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "core/hierarchy/emitter_shape.h"

namespace radiosity {

SampleRgb LinkGather::operator()(std::int32_t e) const {
  SampleRgb h{};
  for (std::uint32_t k = offset[static_cast<size_t>(e)]; k < offset[static_cast<size_t>(e) + 1];
       ++k) {
    const Link& l = links[order[k]];
    const Rgb radiance = sent_radiance(hierarchy, l.emitter, source, l.emitter_shape);
    for (size_t s = 0; s < kMaxSamples; ++s)
      h[s] += static_cast<double>(l.form_factor[s]) * radiance;
  }
  return h;
}

std::array<SampleRgb, 4> push_to_children(const Hierarchy& h, const Element& e,
                                          const SampleRgb& total) {
  const int corners = e.corner_count;
  // The children's interpolants do not reproduce the parent's bubble exactly:
  // a uniform shift makes them carry the same total.
  std::array<SampleRgb, 4> down{};
  glm::dvec3 pushed(0.0);
  for (int c = 0; c < 4; ++c) {
    SampleRgb& child = down[static_cast<size_t>(c)];
    for (int s = 0; s <= corners; ++s)
      child[static_cast<size_t>(s)] = Interpolant::at_child_sample(corners, total, c, s);
    const Element& part = h.element(e.first_child + c);
    pushed += part.area * glm::dvec3(h.average(part, child));
  }
  const Rgb shift = h.average(e, total) - Rgb(pushed / e.area);
  for (SampleRgb& child : down)
    for (int s = 0; s <= corners; ++s) child[static_cast<size_t>(s)] += shift;
  return down;
}

namespace {

// Roots of the hierarchy, for a parallel loop over them.
template <typename Visit>
void for_each_root(const Hierarchy& h, const Visit& visit) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, h.root_count()), [&](const auto& range) {
    for (size_t r = range.begin(); r != range.end(); ++r) {
      const std::int32_t root = h.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
      if (root != kNone) visit(r, root);
    }
  });
}

SampleRgb far_down(const std::vector<SampleRgb>& far_light, std::int32_t root) {
  return far_light.empty() ? SampleRgb{} : far_light[static_cast<size_t>(root)];
}

void gather_down(const Hierarchy& h, std::int32_t index, const SampleRgb& down,
                 const LinkGather& gather, std::vector<SampleRgb>& out) {
  const Element& e = h.element(index);
  SampleRgb total = gather(index);
  for (size_t s = 0; s < kMaxSamples; ++s) total[s] += down[s];
  if (e.is_leaf()) {
    out[static_cast<size_t>(index)] = total;
    return;
  }
  const std::array<SampleRgb, 4> children = push_to_children(h, e, total);
  for (int c = 0; c < 4; ++c)
    gather_down(h, e.first_child + c, children[static_cast<size_t>(c)], gather, out);
}

struct Change {
  double delta = 0.0, total = 0.0;
};

struct PushPull {
  Hierarchy& h;
  const LinkGather& gather;
  const std::vector<SampleScale>& down_scale;
  const std::vector<SampleRgb>& direct;
  const std::vector<Rgb>& by_rays;
  std::vector<SampleRgb>* leaf_out;

  Rgb operator()(std::int32_t index, const SampleRgb& down, Change& change) const;
};

Rgb PushPull::operator()(std::int32_t index, const SampleRgb& down, Change& change) const {
  Element& e = h.element(index);
  SampleRgb total = gather(index);
  const bool scaled = e.is_leaf() && static_cast<size_t>(index) < down_scale.size();
  for (size_t s = 0; s < kMaxSamples; ++s)
    total[s] +=
        scaled ? static_cast<double>(down_scale[static_cast<size_t>(index)][s]) * down[s] : down[s];
  if (static_cast<size_t>(index) < direct.size())
    for (size_t s = 0; s < kMaxSamples; ++s) total[s] += direct[static_cast<size_t>(index)][s];
  if (static_cast<size_t>(index) < by_rays.size())
    for (size_t s = 0; s < kMaxSamples; ++s) total[s] += by_rays[static_cast<size_t>(index)];
  Rgb radiance;
  if (e.is_leaf()) {
    radiance = h.emission(e) + h.reflectance(e) * glm::max(h.average(e, total), Rgb(0.0));
    // Each channel's change, weighted as luminance weighs it: a light turned
    // from white to red at the same luminance (a relight starts from the old
    // solution so scaled) changes every colour but hardly the luminance.
    change.delta += luminance(glm::abs(radiance - e.radiance)) * e.area;
    change.total += luminance(radiance) * e.area;
    if (leaf_out) (*leaf_out)[static_cast<size_t>(index)] = total;
  } else {
    const std::array<SampleRgb, 4> children = push_to_children(h, e, total);
    glm::dvec3 sum(0.0);
    double area = 0.0;
    for (int c = 0; c < 4; ++c) {
      const Rgb child = (*this)(e.first_child + c, children[static_cast<size_t>(c)], change);
      const double child_area = h.element(e.first_child + c).area;
      sum += child_area * glm::dvec3(child);
      area += child_area;
    }
    radiance = Rgb(sum / area);
  }
  h.element(index).radiance = radiance;
  return radiance;
}

}  // namespace

std::vector<SampleRgb> gathered_at_leaves(const Hierarchy& h, const LinkGather& gather,
                                          const std::vector<SampleRgb>& far_light) {
  std::vector<SampleRgb> out(h.elements().size());
  for_each_root(h, [&](size_t, std::int32_t root) {
    gather_down(h, root, far_down(far_light, root), gather, out);
  });
  return out;
}

double push_pull(Hierarchy& h, const LinkGather& gather, const std::vector<SampleRgb>& far_light,
                 const std::vector<SampleScale>& down_scale, const std::vector<SampleRgb>& direct,
                 const std::vector<Rgb>& by_rays, std::vector<SampleRgb>* leaf_out) {
  std::vector<Change> changes(h.root_count());
  const PushPull visit{h, gather, down_scale, direct, by_rays, leaf_out};
  for_each_root(
      h, [&](size_t r, std::int32_t root) { visit(root, far_down(far_light, root), changes[r]); });
  Change sum;
  for (const Change& c : changes) sum.delta += c.delta, sum.total += c.total;
  return sum.total > 0.0 ? sum.delta / sum.total : 0.0;
}

}  // namespace radiosity
