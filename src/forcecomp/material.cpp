#include "uh/forcecomp/material.hpp"

#include <cmath>

#include "uh/core/split_mix.hpp"

namespace uh::forcecomp {
namespace {

double combined_in_series(double a, double b) { return a + b > 0.0 ? a * b / (a + b) : 0.0; }

}  // namespace

double texture_height(const Texture& texture, const Vec3& p_body) {
  switch (texture.kind) {
    case TextureKind::kNone:
      return 0.0;
    case TextureKind::kGrating:
      return texture.amplitude_m * std::sin(2.0 * kPi * dot(texture.direction, p_body) / texture.period_m);
    case TextureKind::kRandom: {
      double sum = 0.0;
      for (const Texture::Wave& w : texture.waves) sum += std::cos(dot(w.wave_vector, p_body) + w.phase);
      return texture.roughness_m * std::sqrt(2.0 / Texture::kWaves) * sum;
    }
  }
  return 0.0;
}

double texture_peak_height(const Texture& texture) {
  switch (texture.kind) {
    case TextureKind::kNone:
      return 0.0;
    case TextureKind::kGrating:
      return texture.amplitude_m;
    case TextureKind::kRandom:
      return texture.roughness_m * std::sqrt(2.0 * Texture::kWaves);
  }
  return 0.0;
}

Texture make_grating(double period_m, double amplitude_m, const Vec3& direction) {
  Texture t;
  t.kind = TextureKind::kGrating;
  t.period_m = period_m;
  t.amplitude_m = amplitude_m;
  t.direction = normalized(direction);
  return t;
}

Texture make_random_texture(double roughness_m, double correlation_length_m, std::uint64_t seed) {
  Texture t;
  t.kind = TextureKind::kRandom;
  t.roughness_m = roughness_m;
  t.correlation_length_m = correlation_length_m;
  t.seed = seed;
  core::SplitMix64 random{seed};
  for (Texture::Wave& w : t.waves) {
    // k ~ N(0, I / l^2): the mean of cos(k . r) is then exp(-|r|^2 / (2 l^2))
    w.wave_vector =
        Vec3{random.normal(), random.normal(), random.normal()} / correlation_length_m;
    w.phase = 2.0 * kPi * random.uniform_open();
  }
  return t;
}

ContactMaterial combine_materials(const Material& object, const Material& tool,
                                  const ForceParams& tool_force) {
  ContactMaterial m;
  const double k_object = object.has_stiffness ? object.stiffness : tool_force.stiffness;
  m.stiffness = tool.has_stiffness ? combined_in_series(k_object, tool.stiffness) : k_object;
  m.damping =
      (object.has_damping ? object.damping : tool_force.damping) + (tool.has_damping ? tool.damping : 0.0);
  if (object.has_friction && tool.has_friction) {
    m.friction_static = std::sqrt(object.friction_static * tool.friction_static);
    m.friction_dynamic = std::sqrt(object.friction_dynamic * tool.friction_dynamic);
  } else if (object.has_friction || tool.has_friction) {
    const Material& side = object.has_friction ? object : tool;
    m.friction_static = side.friction_static;
    m.friction_dynamic = side.friction_dynamic;
  }
  m.object_texture = object.texture;
  m.tool_texture = tool.texture;
  return m;
}

}  // namespace uh::forcecomp
