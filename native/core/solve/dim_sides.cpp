#include "core/solve/dim_sides.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace radiosity {
namespace {

// The top-level sides light reaches that reflect: the ones linking is for.
std::vector<std::int32_t> lit_sides(const Hierarchy& h, const RayPass& pass) {
  std::vector<std::int32_t> out;
  for (std::size_t r = 0; r < h.root_count(); ++r) {
    const std::int32_t id = h.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (id != kNone && h.reflects(h.element(id)) && !pass.unlit[static_cast<std::size_t>(id)])
      out.push_back(id);
  }
  return out;
}

}  // namespace

DimSides::DimSides(const Hierarchy& h, const RayPass& pass, double share) {
  const std::size_t count = pass.gathered.size();
  const auto rays = static_cast<std::size_t>(pass.rays);
  if (!pass.complete || rays == 0 || pass.met.size() != count * rays ||
      pass.unlit.size() != count || pass.lighting_rays.size() != count)
    return;
  const std::vector<std::int32_t> sides = lit_sides(h, pass);
  double area = 0.0, light = 0.0;
  for (std::int32_t id : sides) {
    const double a = h.element(id).area;
    area += a;
    light += a * luminance(pass.gathered[static_cast<std::size_t>(id)]);
  }
  if (!(area > 0.0) || !(light > 0.0)) return;
  const double below = share * light / area;
  std::vector<std::uint8_t> dim(count, 0);
  for (std::int32_t id : sides) {
    const auto i = static_cast<std::size_t>(id);
    if (pass.lighting_rays[i] == 0 && !(luminance(h.emission(h.element(id))) > 0.0) &&
        luminance(pass.gathered[i]) < below) {
      dim[i] = 1;
      ++count_;
    }
  }
  if (!count_) return;
  dim_ = std::move(dim);
  share_to_dim_.assign(count, 0.0f);
  per_ray_ = 1.0 / static_cast<double>(rays);
  first_.push_back(0);
  for (std::int32_t id : sides) {
    const auto i = static_cast<std::size_t>(id);
    std::size_t to_dim = 0;
    for (std::size_t k = 0; k < rays; ++k) {
      const std::int32_t m = pass.met[i * rays + k];
      if (m == kNone || pass.unlit[static_cast<std::size_t>(m)]) continue;
      const bool from_dim = dim_[static_cast<std::size_t>(m)] != 0;
      to_dim += from_dim;
      if (dim_[i] || from_dim) met_.push_back(m);
    }
    share_to_dim_[i] = static_cast<float>(static_cast<double>(to_dim) * per_ray_);
    if (met_.size() > first_.back()) {
      receiver_.push_back(id);
      first_.push_back(static_cast<std::uint32_t>(met_.size()));
    }
  }
  met_.shrink_to_fit();
}

void DimSides::gather(const Hierarchy& h, std::vector<Rgb>& light) const {
  light.assign(dim_.size(), Rgb(0.0));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, receiver_.size()), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      Rgb sum(0.0);
      for (std::uint32_t j = first_[i]; j < first_[i + 1]; ++j) sum += h.element(met_[j]).radiance;
      light[static_cast<std::size_t>(receiver_[i])] = sum * per_ray_;
    }
  });
}

std::size_t DimSides::memory_bytes() const {
  return dim_.capacity() + share_to_dim_.capacity() * sizeof(float) +
         (receiver_.capacity() + met_.capacity()) * sizeof(std::int32_t) +
         first_.capacity() * sizeof(std::uint32_t);
}

}  // namespace radiosity
