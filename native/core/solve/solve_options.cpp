// The names of the solver's enums at the boundary (radiosity/solve.h): each
// table is written once here, and the bindings parse and print through it.
// Also the defaults as JSON, for the add-on's settings.
#include <array>
#include <charconv>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>

#include "radiosity/solve.h"

namespace radiosity {

namespace {

// Each oracle's name, as solve(oracle=...) takes it and the add-on's settings
// (in capitals) store it.
constexpr std::array<std::pair<Oracle, std::string_view>, kOracles.size()> kOracleNames = {{
    {Oracle::Standard, "standard"},
    {Oracle::Perceptual, "perceptual"},
    {Oracle::Gradient, "gradient"},
    {Oracle::Noticeable, "noticeable"},
}};

}  // namespace

std::optional<Oracle> parse_oracle(std::string_view name) {
  for (const auto& [oracle, oracle_name] : kOracleNames)
    if (name == oracle_name) return oracle;
  return std::nullopt;
}

std::string_view oracle_name(Oracle oracle) {
  for (const auto& [each, name] : kOracleNames)
    if (each == oracle) return name;
  return "unknown";
}

std::optional<VisibilityMode> parse_visibility(std::string_view name) {
  if (name == "exact") return VisibilityMode::Exact;
  if (name == "sampled") return VisibilityMode::Sampled;
  return std::nullopt;
}

std::string_view visibility_name(VisibilityMode mode) {
  return mode == VisibilityMode::Exact ? "exact" : "sampled";
}

std::optional<SolveOptions::LeafLinks> parse_leaf_links(std::string_view name) {
  if (name == "none") return SolveOptions::LeafLinks::None;
  if (name == "near") return SolveOptions::LeafLinks::Near;
  if (name == "all") return SolveOptions::LeafLinks::All;
  return std::nullopt;
}

std::string_view leaf_links_name(SolveOptions::LeafLinks links) {
  switch (links) {
    case SolveOptions::LeafLinks::None:
      return "none";
    case SolveOptions::LeafLinks::Near:
      return "near";
    case SolveOptions::LeafLinks::All:
      return "all";
  }
  return "unknown";
}

std::string_view phase_name(SolvePhase phase) {
  switch (phase) {
    case SolvePhase::Linking:
      return "linking";
    case SolvePhase::Refining:
      return "refining";
    case SolvePhase::Gathering:
      return "gathering";
    case SolvePhase::Pass:
      return "pass";
    case SolvePhase::Done:
      return "done";
  }
  return "unknown";
}

std::string_view stop_reason_name(StopReason reason) {
  switch (reason) {
    case StopReason::Quality:
      return "quality";
    case StopReason::MaxElements:
      return "max_elements";
    case StopReason::Memory:
      return "memory";
    case StopReason::TimeBudget:
      return "time_budget";
    case StopReason::Cancel:
      return "cancel";
  }
  return "unknown";
}

std::string_view relight_refusal_name(RelightRefusal refusal) {
  switch (refusal) {
    case RelightRefusal::None:
      return "";
    case RelightRefusal::NothingKept:
      return "nothing_kept";
    case RelightRefusal::OracleChanged:
      return "oracle_changed";
    case RelightRefusal::QualityChanged:
      return "quality_changed";
    case RelightRefusal::VisibilityChanged:
      return "visibility_changed";
    case RelightRefusal::FixedBounces:
      return "fixed_bounces";
    case RelightRefusal::SmallestElementChanged:
      return "smallest_element_changed";
    case RelightRefusal::LinkingChanged:
      return "linking_changed";
    case RelightRefusal::GeometryChanged:
      return "geometry_changed";
    case RelightRefusal::LightsAddedOrRemoved:
      return "lights_added_or_removed";
    case RelightRefusal::LightChanged:
      return "light_changed";
    case RelightRefusal::NowEmits:
      return "now_emits";
    case RelightRefusal::NowReflects:
      return "now_reflects";
  }
  return "unknown";
}

namespace {

// The shortest text that reads back as the same double.
std::string number(double x) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, x).ptr;
  return std::string(text, end);
}

}  // namespace

std::string defaults_json() {
  const SolveOptions d{};
  std::ostringstream out;
  out << "{\n"
      << "  \"oracle\": \"" << oracle_name(d.oracle) << "\",\n"
      << "  \"quality\": " << number(d.quality) << ",\n"
      << "  \"visibility\": \"" << visibility_name(d.visibility) << "\",\n"
      << "  \"rays\": " << d.rays << ",\n"
      << "  \"max_rays\": " << kMaxRays << ",\n"
      << "  \"min_element_area\": " << number(d.min_element_area) << ",\n"
      << "  \"leaf_links\": \"" << leaf_links_name(d.leaf_links) << "\",\n"
      << "  \"tolerance\": " << number(d.tolerance) << ",\n"
      << "  \"max_iterations\": " << d.max_iterations << ",\n"
      << "  \"oracles\": [";
  for (size_t i = 0; i < kOracles.size(); ++i)
    out << (i ? ", " : "") << "\"" << oracle_name(kOracles[i]) << "\"";
  out << "]\n"
      << "}\n";
  return out.str();
}

}  // namespace radiosity
