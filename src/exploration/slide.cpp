#include "slide.hpp"

#include <algorithm>

#include "contact.hpp"
#include "uh/exploration/material_estimate.hpp"

namespace uh::exploration {

Slide slide_of(const ExploreTrace& trace, const std::vector<std::size_t>& idx) {
  Slide s;
  if (idx.size() < 8) return s;
  const auto& x = trace.samples;
  std::vector<double> travel(idx.size(), 0.0);
  for (std::size_t j = 1; j < idx.size(); ++j)
    travel[j] = travel[j - 1] + norm(x[idx[j]].position - x[idx[j - 1]].position);
  const double step = travel.back() / static_cast<double>(idx.size() - 1);
  const auto w = static_cast<std::size_t>(std::clamp(step > 0.0 ? 0.0005 / step : 1.0, 1.0, 2000.0));
  for (std::size_t j = 0; j < idx.size(); ++j) {
    const std::size_t a = j >= w ? j - w : 0, b = std::min(idx.size() - 1, j + w);
    const Vec3 moved = x[idx[b]].position - x[idx[a]].position;
    const Vec3& f = x[idx[j]].force;
    // the hand also moves along the normal to hold its force: only the motion in the tangent plane
    // (across the force, once the force's part along the motion is set aside) is the slide
    const Vec3 first = normalized(moved);
    const Vec3 normal = normalized(f - dot(f, first) * first);
    const Vec3 motion = normalized(moved - dot(moved, normal) * normal);
    if (norm(motion) == 0.0) continue;
    const double along = dot(f, motion);
    const double pressing = norm(f - along * motion);
    if (pressing < kTouchN) continue;
    s.time.push_back(x[idx[j]].time_s);
    s.travel.push_back(travel[j]);
    s.normal_n.push_back(pressing);
    s.friction_ratio.push_back(-along / pressing);
    s.position.push_back(x[idx[j]].position);
    s.force.push_back(f);
  }
  return s;
}

StrokeSlides stroke_slides(const ExploreTrace& trace) {
  const auto& x = trace.samples;
  StrokeSlides out;
  for (int leg = 0; leg < 4; ++leg) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (x[i].phase == ExplorePhase::kStroke && x[i].leg == leg) idx.push_back(i);
    out.legs[leg] = slide_of(trace, idx);
  }
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i].phase == ExplorePhase::kContour) idx.push_back(i);
  out.contour = slide_of(trace, idx);
  return out;
}

std::vector<StrokeForce> stroke_forces(const ExploreTrace& trace) {
  std::vector<StrokeForce> out;
  const auto& x = trace.samples;
  std::size_t i = 0;
  while (i < x.size()) {
    const bool sliding = x[i].phase == ExplorePhase::kStroke || x[i].phase == ExplorePhase::kContour;
    if (!sliding) {
      ++i;
      continue;
    }
    // one stretch: the same phase and leg
    std::vector<std::size_t> idx;
    const ExplorePhase phase = x[i].phase;
    const std::int32_t leg = x[i].leg;
    for (; i < x.size() && x[i].phase == phase && x[i].leg == leg; ++i) idx.push_back(i);
    const Slide s = slide_of(trace, idx);
    for (std::size_t j = 0; j < s.time.size(); ++j)
      out.push_back({s.time[j], s.normal_n[j], s.friction_ratio[j] * s.normal_n[j]});
  }
  return out;
}

}  // namespace uh::exploration
