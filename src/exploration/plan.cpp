#include "plan.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "uh/core/split_mix.hpp"

namespace uh::exploration {
namespace {

// The object's leaf spheres in the world frame and their bounds
struct WorldSpheres {
  std::vector<std::pair<Vec3, double>> spheres;  // centre, radius [m]
  Vec3 lo{1e300, 1e300, 1e300};
  Vec3 hi{-1e300, -1e300, -1e300};
};

WorldSpheres world_spheres(std::span<const Sphere> leaves, const Pose& world_from_object) {
  WorldSpheres w;
  for (const Sphere& s : leaves) {
    const Vec3 c = transform_point(world_from_object, Vec3{static_cast<double>(s.x), static_cast<double>(s.y),
                                                            static_cast<double>(s.z)});
    const double r = static_cast<double>(s.radius);
    w.spheres.emplace_back(c, r);
    w.lo = {std::min(w.lo.x, c.x - r), std::min(w.lo.y, c.y - r), std::min(w.lo.z, c.z - r)};
    w.hi = {std::max(w.hi.x, c.x + r), std::max(w.hi.y, c.y + r), std::max(w.hi.z, c.z + r)};
  }
  return w;
}

// the tool's point that meets the object first, going in along `approach` (the handle holds the
// tool upright: device frame = world)
Vec3 tool_tip(const collette::SphereTree& tool, const Vec3& approach) {
  Vec3 tip{};
  double furthest = -1e300;
  for (const Sphere& s : tool.leaves()) {
    const Vec3 c{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
    const double reach = dot(c, approach) + static_cast<double>(s.radius);
    if (reach > furthest) {
      furthest = reach;
      tip = c + static_cast<double>(s.radius) * approach;
    }
  }
  return tip;
}

// the seed's choices, the same run on every platform
struct Jitter {
  double a = 0.0, b = 0.0;  // across the approach, up to 3 mm each way [m]
  double turn = 0.0;        // of the stroke axes about the vertical [rad]
};

Jitter jitter_of(const ExploreOptions& options) {
  core::SplitMix64 rng{options.seed};
  Jitter j;
  j.a = (rng.uniform() - 0.5) * 0.006;
  j.b = (rng.uniform() - 0.5) * 0.006;
  j.turn = options.stroke_turn_rad.value_or(2.0 * kPi * rng.uniform());
  return j;
}

// down onto the top, at the footprint's middle moved by the site's offset and the seed
ExplorePlan plan_top(const WorldSpheres& w, const Vec3& middle, const collette::SphereTree& tool,
                     const ExploreOptions& options, const Jitter& jitter, double clearance_m) {
  ExplorePlan plan;
  plan.axis_point = middle;
  const Vec3 target{middle.x + options.site.offset_m[0] + jitter.a, middle.y + options.site.offset_m[1] + jitter.b,
                    0.0};
  plan.approach = {0, 0, -1};
  const Vec3 tip = tool_tip(tool, plan.approach);
  // the tip's height where the tool, coming straight down over the target, first meets a sphere of
  // the object: not only the one under the tip (a wide tool over a gap in the packing would start
  // inside its neighbours, and a proxy that begins inside keeps no side)
  double top = -1e300;
  for (const Sphere& t : tool.leaves()) {
    const Vec3 from_tip = Vec3{static_cast<double>(t.x), static_cast<double>(t.y), static_cast<double>(t.z)} - tip;
    const Vec3 centre{target.x + from_tip.x, target.y + from_tip.y, 0.0};
    for (const auto& [c, r] : w.spheres) {
      const double reach = r + static_cast<double>(t.radius);
      const double d2 = (c.x - centre.x) * (c.x - centre.x) + (c.y - centre.y) * (c.y - centre.y);
      if (d2 < reach * reach) top = std::max(top, c.z + std::sqrt(reach * reach - d2) - from_tip.z);
    }
  }
  if (top < -1e299) top = w.hi.z;
  plan.start = Vec3{target.x - tip.x, target.y - tip.y, top + clearance_m - tip.z};
  plan.axes[0] = {std::cos(jitter.turn), std::sin(jitter.turn), 0.0};
  plan.axes[1] = {-std::sin(jitter.turn), std::cos(jitter.turn), 0.0};
  return plan;
}

// side: level towards the centre line from the site's azimuth, at its height (both moved by the seed)
Result<ExplorePlan> plan_side(const WorldSpheres& w, const Vec3& middle, const collette::SphereTree& tool,
                              const ExploreOptions& options, const Jitter& jitter, double clearance_m) {
  ExplorePlan plan;
  plan.axis_point = middle;
  const double azimuth = options.site.azimuth_rad + jitter.a / 0.05;  // up to 3 mm along a 5 cm radius
  const Vec3 out{std::cos(azimuth), std::sin(azimuth), 0.0};
  // (up or down by a third of the seed's move: a band round a coin's edge is a few millimetres high)
  const double z = w.lo.z + std::clamp(options.site.height_fraction, 0.0, 1.0) * (w.hi.z - w.lo.z) + jitter.b / 3.0;
  plan.approach = -out;
  const Vec3 tip = tool_tip(tool, plan.approach);
  // how far out along the level ray from the centre line the tool's tip is where the tool, coming
  // in along it, first meets a sphere of the object (a wide tool, or one over a flaring foot, meets
  // a neighbour before the sphere on the ray: a proxy that begins inside keeps no side)
  double outer = -1e300;
  for (const Sphere& t : tool.leaves()) {
    const Vec3 from_tip = Vec3{static_cast<double>(t.x), static_cast<double>(t.y), static_cast<double>(t.z)} - tip;
    for (const auto& [c, r] : w.spheres) {
      const double reach = r + static_cast<double>(t.radius);
      const Vec3 rel = c - Vec3{middle.x + from_tip.x, middle.y + from_tip.y, z + from_tip.z};
      const double along = dot(rel, out);
      const double across2 = dot(rel, rel) - along * along;
      if (across2 < reach * reach) outer = std::max(outer, along + std::sqrt(reach * reach - across2));
    }
  }
  if (outer < -1e299) return Error{fmt::format("nothing of the object is at height {:.4f} m", z)};
  const Vec3 surface{middle.x + outer * out.x, middle.y + outer * out.y, z};
  plan.start = surface + clearance_m * out - tip;
  plan.axes[0] = {0, 0, 1};
  plan.axes[1] = {-out.y, out.x, 0.0};
  return plan;
}

}  // namespace

Result<ExplorePlan> plan_exploration(const collette::SphereTree& object, const Pose& world_from_object,
                                     const collette::SphereTree& tool, const ExploreOptions& options,
                                     double surface_gap_m) {
  const auto leaves = object.leaves();
  if (leaves.empty()) return Error{"the object has no spheres"};
  const WorldSpheres w = world_spheres(leaves, world_from_object);
  const Jitter jitter = jitter_of(options);
  const Vec3 middle{0.5 * (w.lo.x + w.hi.x), 0.5 * (w.lo.y + w.hi.y), w.lo.z};
  // 3 mm off the spheres, and off the mesh surface the proxy rests on, up to the gap above them
  const double clearance_m = 0.003 + surface_gap_m;
  if (options.site.from == ExploreSite::From::kTop) return plan_top(w, middle, tool, options, jitter, clearance_m);
  return plan_side(w, middle, tool, options, jitter, clearance_m);
}

double leg_length(const ExploreOptions& o, std::int32_t leg) {
  return leg >= 2 ? o.second_stroke_length_m.value_or(o.stroke_length_m) : o.stroke_length_m;
}

Vec3 press_spot(const ExplorePlan& plan, const ExploreOptions& o, int press) {
  const double angle = kPi / 4.0 + kPi / 2.0 * (press - 1);
  return plan.start + o.press_spread_m * (std::cos(angle) * plan.axes[0] + std::sin(angle) * plan.axes[1]);
}

Vec3 stroke_start(const ExplorePlan& plan, const ExploreOptions& o, std::int32_t leg) {
  return plan.start - 0.5 * leg_length(o, leg) * plan.axes[leg / 2];
}

}  // namespace uh::exploration
