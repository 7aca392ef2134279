// Lights that are not surfaces (DESIGN s3): Blender's point, spot and sun
// lights and a uniform world colour. Each is direct light at the receivers'
// samples (direct_light.h), gathered with the links; the hierarchy carries
// its interreflection. Area lights and emissive faces are patches instead.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "radiosity/color.h"
#include "radiosity/vec.h"

namespace radiosity {

enum class LightKind : std::uint8_t { Point, Spot, Sun, Sky };

std::optional<LightKind> parse_light_kind(std::string_view name);

struct Light {
  LightKind kind = LightKind::Point;
  // What a receiver gathers (H, radiance units) per unit of geometry:
  //  point, spot: intensity I, H = I cos(theta) / d^2 (times the spot's attenuation);
  //  sun: H on a surface facing the sun, H = E cos(theta);
  //  sky: the world's radiance, H = L_w times the form factor of the open sky.
  Rgb colour{0.0};
  dvec3 position{0.0};              // point, spot
  dvec3 direction{0.0, 0.0, -1.0};  // unit; spot: its axis; sun: the way its light travels
  // Point, spot: radius of the emitting sphere (Cycles 4.x), or of a disk
  // facing the receiver (`sphere` false: Cycles 3.x); 0 is a point.
  double radius = 0.0;
  bool sphere = true;
  double angle = 0.0;  // sun: angular diameter of its disk, radians
  // Spot: the factor on I in a direction at cosine c to the axis is
  // (c if cosine_falloff) x smoothstep((c - cos_half_angle) / blend_width),
  // a step where blend_width is 0.
  double cos_half_angle = -1.0;
  double blend_width = 0.0;
  bool cosine_falloff = false;
};

// Throws std::invalid_argument naming what is wrong (non-finite values,
// negative colour or radius, zero direction, cone parameters out of range).
void check_light(const Light& light, std::size_t index);

}  // namespace radiosity
