#include "uh/forcecomp/wrench_model.hpp"

#include <algorithm>
#include <cmath>

#include "uh/core/sphere_overlap.hpp"

namespace uh::forcecomp {

namespace {

Vec3 centre(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

struct M3 {
  double a[3][3] = {};
};

M3 skew(const Vec3& v) {
  M3 m;
  m.a[0][1] = -v.z;
  m.a[0][2] = v.y;
  m.a[1][0] = v.z;
  m.a[1][2] = -v.x;
  m.a[2][0] = -v.y;
  m.a[2][1] = v.x;
  return m;
}

M3 mul(const M3& x, const M3& y) {
  M3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      m.a[i][j] = x.a[i][0] * y.a[0][j] + x.a[i][1] * y.a[1][j] + x.a[i][2] * y.a[2][j];
  return m;
}

// adds `scale` * m into the 3x3 block of `out` at (row, col)
void add_block(Matrix6& out, int row, int col, const M3& m, double scale = 1.0) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[row + i][col + j] += scale * m.a[i][j];
}

double component(const Vec3& v, int i) { return i == 0 ? v.x : (i == 1 ? v.y : v.z); }

// d(area)/dd of the lens kernel's intersection disk area pi a^2 = pi/4 (S^2 - d^2)(d^2 - delta^2) / d^2
// (sphere_overlap.hpp); 0 apart and in containment, where the area is 0
double area_derivative(double d, double r1, double r2) {
  const double sum = r1 + r2;
  const double delta = r1 - r2;
  if (!(d < sum) || !(d > std::abs(delta))) return 0.0;
  const double q = delta * delta / (d * d);
  return kPi / 4.0 * (-2.0 * d * (1.0 - q) + (sum * sum - d * d) * 2.0 * q / d);
}

}  // namespace

WrenchModel build_wrench_model(std::span<const SpherePairContact> pairs, const Pose& world_from_a,
                               const Pose& world_from_b, const PenaltyInput& input,
                               const WrenchModelOptions& options) {
  WrenchModel m;
  const bool tool_is_b = input.tool_side == ContactSide::kB;
  const Pose& world_from_tool = tool_is_b ? world_from_b : world_from_a;
  const Pose& world_from_other = tool_is_b ? world_from_a : world_from_b;
  const double normal_sign = tool_is_b ? 1.0 : -1.0;  // Collette's normals run from a to b
  const Vec3 am = input.tool.center_of_mass_world;
  m.six_dof = input.mode == ForceMode::k6Dof;
  m.tool_rotation = world_from_tool.rotation;
  m.center_of_mass_world = am;
  m.world_from_tool = world_from_tool;
  m.world_from_other = world_from_other;
  Vec3 volume_moment{};
  const bool gradient = input.law == ForceLaw::kGradient;
  const double calibration = gradient ? coverage_product(input) : 1.0;
  const double per_area = input.stiffness / calibration;
  const double per_volume = input.force_scale;

  double total = 0.0;
  Matrix6 volume_jj{};  // sum vol j j^T, scaled into D once Vol_total is known
  double weight = 0.0, weighted_radius = 0.0, weighted_lever2 = 0.0;
  double plain_radius = 0.0, plain_lever2 = 0.0;
  for (const SpherePairContact& p : pairs) {
    const Sphere& so = tool_is_b ? p.sphere_a_local : p.sphere_b_local;
    const Sphere& st = tool_is_b ? p.sphere_b_local : p.sphere_a_local;
    const Vec3 co = transform_point(world_from_other, centre(so));
    const Vec3 ct = transform_point(world_from_tool, centre(st));
    const double r_other = static_cast<double>(so.radius);
    const double r_tool = static_cast<double>(st.radius);
    const Vec3 delta = ct - co;
    const double d = norm(delta);
    const SphereOverlap<double> o = sphere_overlap(d, r_other, r_tool);
    if (!(o.volume > 0.0) || !std::isfinite(o.volume)) continue;
    ++m.pair_count;
    total += o.volume;
    // coincident centres leave the centre line to the query's normal, and no sideways stiffness
    const bool has_line = d > 1e-6 * (r_other + r_tool);
    const Vec3 n = has_line ? delta / d
                            : normal_sign * Vec3{static_cast<double>(p.normal_world[0]),
                                                 static_cast<double>(p.normal_world[1]),
                                                 static_cast<double>(p.normal_world[2])};
    volume_moment += o.volume * (co + o.centroid_offset * n);
    m.volume_gradient_world -= o.area * n;
    const double s = gradient ? per_area * o.area : per_volume * o.volume;
    const double ds = gradient ? per_area * area_derivative(d, r_other, r_tool) : -per_volume * o.area;
    const Vec3 ro = co - am;
    const Vec3 rt = ct - am;
    const Vec3 j_rot = cross(ro, n);
    const double j[6] = {n.x, n.y, n.z, j_rot.x, j_rot.y, j_rot.z};
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) volume_jj[r][c] += o.volume * j[r] * j[c];
    plain_radius += std::min(r_other, r_tool);
    plain_lever2 += squared_norm(rt);
    if (!(s > 0.0)) continue;  // containment under the gradient law: no area, no push

    const Vec3 f = s * n;
    m.wrench.force += f;
    m.wrench.torque += cross(ro, f);
    const double lateral = has_line ? s / d : 0.0;
    M3 k;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        k.a[r][c] = (ds - lateral) * component(n, r) * component(n, c) + (r == c ? lateral : 0.0);
    const M3 k_rt = mul(k, skew(rt));
    const M3 ro_k = mul(skew(ro), k);
    add_block(m.stiffness, 0, 0, k);
    add_block(m.stiffness, 0, 3, k_rt, -1.0);
    add_block(m.stiffness, 3, 0, skew(f));
    add_block(m.stiffness, 3, 0, ro_k);
    add_block(m.stiffness, 3, 3, mul(ro_k, skew(rt)), -1.0);
    weight += s;
    weighted_radius += s * std::min(r_other, r_tool);
    weighted_lever2 += s * squared_norm(rt);
  }
  m.total_volume = total;
  if (m.pair_count == 0) return m;  // nothing overlaps: the zero wrench
  m.contact = true;
  m.volume_centroid_world = (1.0 / total) * volume_moment;

  const double damping_scale = input.damping / std::max(total, damping_full_volume(input) * calibration);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m.damping[r][c] = damping_scale * volume_jj[r][c];

  const double count = static_cast<double>(m.pair_count);
  const double radius = weight > 0.0 ? weighted_radius / weight : plain_radius / count;
  const double lever = std::sqrt(weight > 0.0 ? weighted_lever2 / weight : plain_lever2 / count);
  m.trust_translation = std::max(options.trust_fraction, 1e-6) * radius;
  m.trust_rotation = m.trust_translation / std::max(lever, radius);

  if (!m.six_dof) {
    m.wrench.torque = {};
    for (int r = 3; r < 6; ++r)
      for (int c = 0; c < 6; ++c) m.stiffness[r][c] = m.damping[r][c] = 0.0;
  }
  return m;
}

WrenchModel build_wrench_model(const ContactFrame& frame, const PenaltyInput& input,
                               const WrenchModelOptions& options) {
  const auto count = static_cast<std::size_t>(std::clamp(frame.pair_count, 0, ContactFrame::kMaxPairs));
  WrenchModel m = build_wrench_model(std::span<const SpherePairContact>(frame.pairs.data(), count),
                                     frame.world_from_a, frame.world_from_b, input, options);
  m.sequence = frame.sequence;
  m.time_s = frame.time_s;
  return m;
}

WrenchModelSample evaluate_wrench_model(const WrenchModel& model, const Quat& tool_rotation,
                                        const BodyMotion& tool, const BodyMotion& other) {
  WrenchModelSample out;
  if (!model.contact) return out;
  Vec3 t = tool.center_of_mass_world - model.center_of_mass_world;
  Vec3 theta = rotation_vector(tool_rotation * conjugate(model.tool_rotation));
  out.reach = std::max(norm(t) / model.trust_translation, norm(theta) / model.trust_rotation);
  if (out.reach > 1.0) {
    // back onto the trust boundary along the same direction of motion
    t = (1.0 / out.reach) * t;
    theta = (1.0 / out.reach) * theta;
  }
  const Vec3 v = tool.linear_velocity_world - other.point_velocity(tool.center_of_mass_world);
  const Vec3 w = tool.angular_velocity_world - other.angular_velocity_world;
  const double x[6] = {t.x, t.y, t.z, theta.x, theta.y, theta.z};
  const double twist[6] = {v.x, v.y, v.z, w.x, w.y, w.z};
  double y[6] = {model.wrench.force.x,  model.wrench.force.y,  model.wrench.force.z,
                 model.wrench.torque.x, model.wrench.torque.y, model.wrench.torque.z};
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) y[r] += model.stiffness[r][c] * x[c] - model.damping[r][c] * twist[c];
  out.wrench = {{y[0], y[1], y[2]}, {y[3], y[4], y[5]}};
  return out;
}

void WrenchModelRenderer::take(const WrenchModel& model) {
  if (have_model_ && model.time_s > model_.time_s) frame_interval_s_ = model.time_s - model_.time_s;
  model_ = model;
  have_model_ = true;
  rebase_ = true;
}

void WrenchModelRenderer::reset() { *this = WrenchModelRenderer(options_); }

bool WrenchModelRenderer::active(double now_s) const {
  return have_model_ && (model_.contact || rebase_ || holding_ || now_s < blend_start_s_ + blend_s_);
}

Wrench WrenchModelRenderer::render(double now_s, const Quat& tool_rotation, const BodyMotion& tool,
                                   const BodyMotion& other) {
  const WrenchModelSample sample = evaluate_wrench_model(model_, tool_rotation, tool, other);
  const bool beyond = model_.contact && !(sample.reach <= std::max(options_.hold_beyond, 1.0));
  if (beyond && have_last_) {
    // the model means nothing this far out: keep what was felt until a frame or the tool comes back
    ++held_ticks_;
    holding_ = true;
    last_s_ = now_s;
    return last_;
  }
  if (holding_) {
    holding_ = false;
    rebase_ = true;
  }
  if (sample.reach > 1.0) ++clamped_ticks_;
  if (rebase_) {
    rebase_ = false;
    offset_.force = have_last_ ? last_.force - sample.wrench.force : Vec3{};
    offset_.torque = have_last_ ? last_.torque - sample.wrench.torque : Vec3{};
    blend_start_s_ = have_last_ ? last_s_ : now_s;
    const double interval = frame_interval_s_ > 0.0 ? frame_interval_s_ : 0.01;
    blend_s_ = std::clamp(options_.blend_s > 0.0 ? options_.blend_s : interval, kMinBlendS, kMaxBlendS);
  }
  const double fade = blend_s_ > 0.0 ? std::clamp(1.0 - (now_s - blend_start_s_) / blend_s_, 0.0, 1.0) : 0.0;
  Wrench out = sample.wrench;
  out.force += fade * offset_.force;
  out.torque += fade * offset_.torque;
  last_ = out;
  last_s_ = now_s;
  have_last_ = true;
  return out;
}

}  // namespace uh::forcecomp
