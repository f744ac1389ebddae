#include "slide.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "contact.hpp"
#include "plan.hpp"
#include "uh/exploration/material_estimate.hpp"

namespace uh::exploration {
namespace {

// the contact moved less than this share of the hand's travel: it sticks, and the hand's pull is
// the way it will slide
constexpr double kStuckShare = 0.25;
// the stick's ramp (the force along the surface per metre the hand pulls) within this factor of the
// contact's stiffness: one spring holds the tool to the hand along the surface as across it
constexpr double kSameSpring = 1.4;

// the direction of `moved` in the tangent plane of the force `f` (the hand also moves along the
// normal, to hold its force or over a curve: that is no slide), zero when it has none
Vec3 tangent_motion(const Vec3& moved, const Vec3& f) {
  const Vec3 first = normalized(moved);
  const Vec3 normal = normalized(f - dot(f, first) * first);
  return normalized(moved - dot(moved, normal) * normal);
}

std::vector<std::size_t> samples_of(const ExploreTrace& trace, ExplorePhase phase, std::int32_t leg) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < trace.samples.size(); ++i)
    if (trace.samples[i].phase == phase && (leg < 0 || trace.samples[i].leg == leg)) idx.push_back(i);
  return idx;
}

// The stick's ramp of one stroke, from rest: the force against the hand's pull over the hand's
// travel until it first reaches half its largest value over the stroke's first third [N/m]; 0 when
// the stroke has none.
double stick_ramp(const Slide& hand, double third_m) {
  double peak = 0.0;
  for (std::size_t j = 0; j < hand.travel.size() && hand.travel[j] < third_m; ++j) peak = std::max(peak, hand.pulled_n[j]);
  for (std::size_t j = 1; j < hand.travel.size() && peak > 0.0; ++j)
    if (hand.pulled_n[j] >= 0.5 * peak && hand.travel[j] > hand.travel[0])
      return (hand.pulled_n[j] - hand.pulled_n[0]) / (hand.travel[j] - hand.travel[0]);
  return 0.0;
}

}  // namespace

Slide slide_of(const ExploreTrace& trace, const std::vector<std::size_t>& idx, double stiffness,
               double sunk_stiffness) {
  Slide s;
  if (idx.size() < 8) return s;
  const auto& x = trace.samples;
  std::vector<Vec3> contact(idx.size());
  for (std::size_t j = 0; j < idx.size(); ++j)
    contact[j] = stiffness > 0.0 ? x[idx[j]].position + x[idx[j]].force / stiffness : x[idx[j]].position;
  double hand_travel = 0.0;
  for (std::size_t j = 1; j < idx.size(); ++j) hand_travel += norm(x[idx[j]].position - x[idx[j - 1]].position);
  const double step = hand_travel / static_cast<double>(idx.size() - 1);
  const auto w = static_cast<std::size_t>(std::clamp(step > 0.0 ? 0.0005 / step : 1.0, 1.0, 2000.0));
  double travel = 0.0;
  for (std::size_t j = 0; j < idx.size(); ++j) {
    const std::size_t a = j >= w ? j - w : 0, b = std::min(idx.size() - 1, j + w);
    const Vec3& f = x[idx[j]].force;
    const Vec3 pulled = x[idx[b]].position - x[idx[a]].position;
    const Vec3 slid = contact[b] - contact[a];
    const Vec3 motion = tangent_motion(norm(slid) >= kStuckShare * norm(pulled) ? slid : pulled, f);
    const double along = dot(f, motion);
    const double pressing = norm(f - along * motion);
    const Vec3 across = pressing > 0.0 ? (f - along * motion) / pressing : Vec3{};
    // the travel along the surface: the contact also rides a texture's relief (a 0.1 mm grating of
    // 2.5 mm lengthens the path by 1.6 %) and, between the proxy's steps, slides off it along its
    // tangent (at 10 kHz and ten ticks a step, 4 %); neither is a way along the surface
    if (j > 0) {
      const Vec3 moved = contact[j] - contact[j - 1];
      travel += norm(moved - dot(moved, across) * across);
    }
    if (norm(motion) == 0.0 || pressing < kTouchN) continue;
    s.time.push_back(x[idx[j]].time_s);
    s.travel.push_back(travel);
    s.normal_n.push_back(pressing);
    s.friction_ratio.push_back(-along / pressing);
    s.pulled_n.push_back(-dot(f, tangent_motion(pulled, f)));
    s.position.push_back(x[idx[j]].position);
    s.contact.push_back(contact[j]);
    s.centre.push_back(sunk_stiffness > 0.0 ? contact[j] + (pressing / sunk_stiffness) * across : contact[j]);
    s.force.push_back(f);
  }
  return s;
}

bool hand_spring_holds_the_tool(const ExploreTrace& trace, double stiffness) {
  if (!(stiffness > 0.0)) return false;
  std::vector<double> ramps;
  for (std::int32_t leg = 0; leg < 4; ++leg) {
    const double ramp = stick_ramp(slide_of(trace, samples_of(trace, ExplorePhase::kStroke, leg), 0.0, 0.0),
                                   leg_length(trace.options, leg) / 3.0);
    if (ramp > 0.0) ramps.push_back(ramp);
  }
  if (ramps.empty()) return false;
  std::nth_element(ramps.begin(), ramps.begin() + static_cast<std::ptrdiff_t>(ramps.size() / 2), ramps.end());
  const double ramp = ramps[ramps.size() / 2];
  return ramp < kSameSpring * stiffness && ramp * kSameSpring > stiffness;
}

StrokeSlides stroke_slides(const ExploreTrace& trace, double stiffness) {
  const bool coupled = hand_spring_holds_the_tool(trace, stiffness);
  const double spring = coupled ? stiffness : 0.0, sunk = coupled ? 0.0 : stiffness;
  StrokeSlides out;
  for (std::int32_t leg = 0; leg < 4; ++leg)
    out.legs[leg] = slide_of(trace, samples_of(trace, ExplorePhase::kStroke, leg), spring, sunk);
  out.contour = slide_of(trace, samples_of(trace, ExplorePhase::kContour, -1), spring, sunk);
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
    const Slide s = slide_of(trace, idx, 0.0, 0.0);  // the handle's frame, as the device felt it
    for (std::size_t j = 0; j < s.time.size(); ++j)
      out.push_back({s.time[j], s.normal_n[j], s.friction_ratio[j] * s.normal_n[j]});
  }
  return out;
}

}  // namespace uh::exploration
