#include "uh/controllers/soft_simulation.hpp"

#include <algorithm>
#include <utility>

#include <fmt/format.h>

namespace uh::controllers {

Result<std::unique_ptr<SoftSimulation>> SoftSimulation::create(std::shared_ptr<const soft::SoftBodyModel> body,
                                                               std::shared_ptr<const collette::SphereTree> rest_tree,
                                                               const Pose& world_from_object, std::size_t tools) {
  if (!body || !rest_tree || !rest_tree->refittable() ||
      static_cast<std::size_t>(rest_tree->leaf_count()) != body->spheres.size())
    return Error{"soft simulation: the tree is not the soft body's packing, or cannot be refitted", ErrorKind::kInvalid};
  auto fem = soft::CorotationalFem::create(body->mesh, body->material, body->fixed);
  if (!fem) return fem.error();
  return std::unique_ptr<SoftSimulation>(
      new SoftSimulation(std::move(body), std::move(rest_tree), std::move(*fem), world_from_object, tools));
}

SoftSimulation::SoftSimulation(std::shared_ptr<const soft::SoftBodyModel> body,
                               std::shared_ptr<const collette::SphereTree> rest_tree, soft::CorotationalFem fem,
                               const Pose& world_from_object, std::size_t tools)
    : body_(std::move(body)),
      rest_tree_(std::move(rest_tree)),
      fem_(std::move(fem)),
      object_from_world_(conjugate(world_from_object.rotation)),
      loads_(body_->mesh.nodes.size(), Eigen::Vector3d::Zero()),
      spheres_(rest_tree_->leaves().begin(), rest_tree_->leaves().end()),
      down_in_object_(rotate(object_from_world_, Vec3{0.0, 0.0, -1.0})) {
  record_.reserve(kRecordCapacity);
  for (std::size_t t = 0; t < tools; ++t) {
    contacts_.push_back(std::make_unique<LatestValue<SoftContacts>>());
    tool_forces_.push_back(std::make_unique<LatestValue<Vec3>>());
  }
}

void SoftSimulation::post_contacts(std::size_t tool, std::int32_t object, const ContactFrame& frame) {
  // another object's own frame says nothing of this one (a tool against everything says all)
  if (frame.object_a != object && frame.object_a != ContactFrame::kEveryObject) return;
  std::span<const SpherePairContact> pairs;
  double share = 0.0;
  if (frame.object_a == object) {
    pairs = frame.pairs();
    share = 1.0;
  } else if (frame.object_a == ContactFrame::kEveryObject) {
    for (const ContactSection& s : frame.sections()) {
      if (s.object_a != object) continue;
      pairs = frame.pairs().subspan(static_cast<std::size_t>(s.first_pair), static_cast<std::size_t>(s.pair_count));
      share = frame.total_volume > 0.0 ? s.total_volume / frame.total_volume : 0.0;
    }
  }
  SoftContacts& out = contacts_[tool]->write_buffer();
  out.count = 0;
  out.share = share;
  for (const SpherePairContact& p : pairs) {
    if (out.count == SoftContacts::kCapacity) break;
    if (!(p.volume > 0.f) || p.leaf_a < 0 || static_cast<std::size_t>(p.leaf_a) >= body_->spheres.size()) continue;
    out.leaves[static_cast<std::size_t>(out.count)] = p.leaf_a;
    out.weights[static_cast<std::size_t>(out.count)] = p.volume;
    ++out.count;
  }
  contacts_[tool]->publish();
}

void SoftSimulation::post_tool_force(std::size_t tool, const Vec3& force_world) { tool_forces_[tool]->write(force_world); }

// Each tool's felt force, this object's share of it, back on the object's contact spheres with
// the opposite sign, spread by their overlap volumes: the loads sum to minus what the tools felt.
void SoftSimulation::gather_loads() {
  std::fill(loads_.begin(), loads_.end(), Eigen::Vector3d::Zero());
  for (std::size_t t = 0; t < contacts_.size(); ++t) {
    contacts_[t]->update();
    tool_forces_[t]->update();
    const SoftContacts& c = contacts_[t]->read_buffer();
    double total = 0.0;
    for (std::int32_t i = 0; i < c.count; ++i) total += static_cast<double>(c.weights[static_cast<std::size_t>(i)]);
    if (!(total > 0.0) || !tool_forces_[t]->has_value()) continue;
    const Vec3 f = rotate(object_from_world_, tool_forces_[t]->read_buffer()) * (-c.share / total);
    const Eigen::Vector3d per_volume(f.x, f.y, f.z);
    for (std::int32_t i = 0; i < c.count; ++i) {
      const auto k = static_cast<std::size_t>(i);
      soft::spread_sphere_force(*body_, c.leaves[k], static_cast<double>(c.weights[k]) * per_volume, loads_);
    }
  }
}

Status SoftSimulation::step(double dt_s) {
  gather_loads();
  if (Status s = fem_.step(dt_s, loads_); !s) return s;
  soft::deform_spheres(*body_, fem_.positions(), spheres_);
  collette::SphereTree& tree = trees_.write_buffer();
  // a slot the reader never handed back before holds no tree yet: it gets the rest tree once
  if (tree.node_count() != rest_tree_->node_count()) tree = *rest_tree_;
  tree.refit(spheres_);
  trees_.publish();
  publish_surface(dt_s);
  return Ok{};
}

void SoftSimulation::publish_surface(double dt_s) {
  SoftSurface& surface = surfaces_.write_buffer();
  // a slot's storage is sized the first time it comes round, as the trees' are
  surface.xyz.resize(3 * surface_vertex_count());
  soft::deform_surface(*body_, fem_.positions(), surface.xyz);
  surface.step = ++steps_;
  record_step(dt_s, surface.xyz);
  surfaces_.publish();
}

void SoftSimulation::record_step(double dt_s, std::span<const float> xyz) {
  if (record_.size() == record_.capacity()) return;  // full: no allocation on this thread
  const auto& rest = body_->surface.vertices;
  double deepest = 0.0;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    const Vec3 moved{static_cast<double>(xyz[3 * i]) - rest[i].x(), static_cast<double>(xyz[3 * i + 1]) - rest[i].y(),
                     static_cast<double>(xyz[3 * i + 2]) - rest[i].z()};
    deepest = std::max(deepest, dot(moved, down_in_object_));
  }
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (const auto& l : loads_) total += l;
  record_.push_back({.time_s = static_cast<double>(steps_) * dt_s, .indentation_m = deepest, .force_n = total.norm()});
}

std::uint64_t SoftSimulation::read_surface(std::span<float> xyz) {
  const std::lock_guard lock(surface_readers_);
  surfaces_.update();
  const SoftSurface& newest = surfaces_.read_buffer();
  if (newest.step == 0) {  // no step yet: the rest surface
    soft::deform_surface(*body_, body_->mesh.nodes, xyz);
    return 0;
  }
  const std::size_t n = std::min(xyz.size() / 3 * 3, newest.xyz.size());
  std::copy_n(newest.xyz.begin(), n, xyz.begin());
  return newest.step;
}

Status SoftSimulation::start(double rate_hz) {
  // no spinning before each deadline: the simulation shares the machine's cores with the haptic
  // and collision threads, and a millisecond late is nothing at its rate
  loop_ = std::make_unique<FixedRateLoop>(FixedRateLoopOptions{.rate_hz = rate_hz, .spin_us = 0.0, .name = "uh-soft"});
  const double dt_s = 1.0 / rate_hz;
  return loop_->start([this, dt_s](const TickInfo&) {
    // a fixed step whatever the tick's lateness: the simulation's time is its own
    if (Status s = step(dt_s); !s) {
      failure_ = s;
      loop_->request_stop();
    }
  });
}

void SoftSimulation::stop() {
  if (loop_) loop_->stop();
}

}  // namespace uh::controllers
