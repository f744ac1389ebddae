#include "uh/forcecomp/material.hpp"

#include <cmath>

namespace uh::forcecomp {
namespace {

// splitmix64: a small generator whose output is the same on every platform and standard library
// (std::normal_distribution is not), so a seed names one surface everywhere
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // uniform in (0, 1): never 0, so the logarithm below is finite
  double uniform() { return (static_cast<double>(next() >> 11) + 0.5) * 0x1.0p-53; }
  // standard normal (Box-Muller)
  double normal() {
    const double r = std::sqrt(-2.0 * std::log(uniform()));
    return r * std::cos(2.0 * kPi * uniform());
  }
};

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
  SplitMix64 rng{seed};
  for (Texture::Wave& w : t.waves) {
    // k ~ N(0, I / l^2): the mean of cos(k . r) is then exp(-|r|^2 / (2 l^2))
    w.wave_vector = Vec3{rng.normal(), rng.normal(), rng.normal()} / correlation_length_m;
    w.phase = 2.0 * kPi * rng.uniform();
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
