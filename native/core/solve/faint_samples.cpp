#include "core/solve/faint_samples.h"

namespace radiosity {

FaintSamples::FaintSamples(const Hierarchy& h, const RayPass& pass, double share) {
  const std::size_t count = pass.gathered.size();
  if (!pass.complete || !(share > 0.0) || count == 0) return;
  sends_.resize(count);
  below_.resize(count);
  for (std::size_t id = 0; id < count; ++id) {
    const Element& side = h.element(static_cast<std::int32_t>(id));
    const Rgb& gathered = pass.gathered[id];
    sends_[id] = static_cast<float>(luminance(h.emission(side) + h.reflectance(side) * gathered));
    below_[id] = static_cast<float>(share * luminance(gathered));
  }
}

}  // namespace radiosity
