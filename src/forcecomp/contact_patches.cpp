#include "uh/forcecomp/contact_patches.hpp"

#include <algorithm>
#include <cmath>

namespace uh::forcecomp {

namespace {

// boxes kept while the pairs are read (separate regions beyond it join their nearest)
constexpr std::int32_t kWorkingPatches = 16;

using Patch = ContactPatches::Patch;

Vec3 centroid_of(const SpherePairContact& p) {
  return {static_cast<double>(p.centroid_world[0]), static_cast<double>(p.centroid_world[1]),
          static_cast<double>(p.centroid_world[2])};
}

// distance from a point to a box (0 inside)
double distance(const Patch& b, const Vec3& p) {
  const Vec3 out{std::max({b.lo.x - p.x, 0.0, p.x - b.hi.x}), std::max({b.lo.y - p.y, 0.0, p.y - b.hi.y}),
                 std::max({b.lo.z - p.z, 0.0, p.z - b.hi.z})};
  return norm(out);
}

// gap between two boxes (0 when they overlap)
double gap(const Patch& a, const Patch& b) {
  const Vec3 out{std::max({a.lo.x - b.hi.x, 0.0, b.lo.x - a.hi.x}),
                 std::max({a.lo.y - b.hi.y, 0.0, b.lo.y - a.hi.y}),
                 std::max({a.lo.z - b.hi.z, 0.0, b.lo.z - a.hi.z})};
  return norm(out);
}

void merge_into(Patch& into, const Patch& from) {
  into.lo = {std::min(into.lo.x, from.lo.x), std::min(into.lo.y, from.lo.y), std::min(into.lo.z, from.lo.z)};
  into.hi = {std::max(into.hi.x, from.hi.x), std::max(into.hi.y, from.hi.y), std::max(into.hi.z, from.hi.z)};
  into.volume += from.volume;
  into.link = std::max(into.link, from.link);
}

// removes box i (the last one takes its place)
void remove(Patch* boxes, std::int32_t& count, std::int32_t i) { boxes[i] = boxes[--count]; }

}  // namespace

std::int32_t ContactPatches::patch_of(const SpherePairContact& pair) const {
  if (count <= 1) return 0;
  const Vec3 c = centroid_of(pair);
  std::int32_t best = 0;
  double best_distance = distance(patch[0], c);
  for (std::int32_t i = 1; i < count && best_distance > 0.0; ++i) {
    const double d = distance(patch[i], c);
    if (d < best_distance) {
      best = i;
      best_distance = d;
    }
  }
  return best;
}

ContactPatches find_contact_patches(std::span<const SpherePairContact> pairs) {
  Patch boxes[kWorkingPatches];
  std::int32_t count = 0;
  for (const SpherePairContact& p : pairs) {
    if (!(p.volume > 0.f)) continue;
    const Vec3 c = centroid_of(p);
    if (!is_finite(c)) continue;
    const double link =
        kPatchLinkRadii * static_cast<double>(std::min(p.sphere_a_local.radius, p.sphere_b_local.radius));
    const Patch own{c, c, static_cast<double>(p.volume), link};
    // join every box it links to; they become one
    std::int32_t joined = -1;
    for (std::int32_t i = 0; i < count;) {
      if (distance(boxes[i], c) < std::max(boxes[i].link, link)) {
        if (joined < 0) {
          joined = i;
          merge_into(boxes[i], own);
        } else {
          merge_into(boxes[joined], boxes[i]);
          remove(boxes, count, i);  // the last box (after `joined`) moved into slot i
          continue;
        }
      }
      ++i;
    }
    if (joined >= 0) continue;
    if (count < kWorkingPatches) {
      boxes[count++] = own;
      continue;
    }
    std::int32_t nearest = 0;
    for (std::int32_t i = 1; i < count; ++i)
      if (distance(boxes[i], c) < distance(boxes[nearest], c)) nearest = i;
    merge_into(boxes[nearest], own);
  }
  // boxes that grew into each other's reach are one region
  for (bool merged = true; merged;) {
    merged = false;
    for (std::int32_t i = 0; i < count && !merged; ++i)
      for (std::int32_t j = i + 1; j < count && !merged; ++j)
        if (gap(boxes[i], boxes[j]) < std::max(boxes[i].link, boxes[j].link)) {
          merge_into(boxes[i], boxes[j]);
          remove(boxes, count, j);
          merged = true;
        }
  }
  // at most kMaxContactPatches: the one of least volume joins the nearest
  while (count > kMaxContactPatches) {
    std::int32_t smallest = 0;
    for (std::int32_t i = 1; i < count; ++i)
      if (boxes[i].volume < boxes[smallest].volume) smallest = i;
    std::int32_t nearest = smallest == 0 ? 1 : 0;
    for (std::int32_t i = 0; i < count; ++i)
      if (i != smallest && gap(boxes[i], boxes[smallest]) < gap(boxes[nearest], boxes[smallest])) nearest = i;
    merge_into(boxes[nearest], boxes[smallest]);
    remove(boxes, count, smallest);
  }
  ContactPatches out;
  out.count = count;
  for (std::int32_t i = 0; i < count; ++i) out.patch[i] = boxes[i];
  return out;
}

}  // namespace uh::forcecomp
