#include "uh/forcecomp/wrench_model.hpp"

#include <algorithm>
#include <cmath>

#include "uh/core/sphere_overlap.hpp"

namespace uh::forcecomp {

namespace {

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

double component(const Vec3& v, int i) { return i == 0 ? v.x : (i == 1 ? v.y : v.z); }

// d(area)/dd of the lens kernel's intersection disk area pi a^2 = pi/4 (S^2 - d^2)(d^2 - delta^2) / d^2
// (sphere_overlap.hpp); 0 apart and in containment, where the area is 0
// (`inv_d` = 1 / d, which the caller has)
double area_derivative(double d, double inv_d, double r1, double r2) {
  const double sum = r1 + r2;
  const double delta = r1 - r2;
  if (!(d < sum) || !(d > std::abs(delta))) return 0.0;
  const double q = delta * delta * inv_d * inv_d;
  return kPi / 4.0 * (-2.0 * d * (1.0 - q) + (sum * sum - d * d) * 2.0 * q * inv_d);
}

// The sums over a frame's pairs that the model is assembled from. Per pair K = a n n^T + b I
// (a = s' - s/d, b = s/d); the four blocks of S are sums of products of K with [r_o]x and [r_t]x,
// which split into these sums (with [x]x [y]x = y x^T - (x . y) I):
//   dF/dt = P + B I                      P = sum a n n^T,              B = sum b
//   dF/dtheta = -(Q + [R]x)              Q = sum a n (n x r_t)^T,      R = sum b r_t
//   dtau/dt = [F]x + U + [R_o]x          U = sum a (r_o x n) n^T,      R_o = sum b r_o
//   dtau/dtheta = -(V + W - w I)         V = sum a (r_o x n)(n x r_t)^T, W = sum b r_t r_o^T, w = sum b r_o
//   . r_t
struct PairSums {
  M3 sum_p, sum_q, sum_u, sum_v, sum_w;
  double sum_b = 0.0, sum_bw = 0.0;
  Vec3 sum_r{}, sum_ro{};
  Matrix6 volume_jj{};  // sum vol j j^T (upper triangle), scaled into D once Vol_total is known
  Vec3 volume_moment{};
  double total = 0.0;
  double all_volume = 0.0;  // of every pair, selected or not: it scales the damping
  double weight = 0.0, weighted_radius = 0.0, weighted_lever2 = 0.0;
  double plain_radius = 0.0, plain_lever2 = 0.0;

  // one pair's K (push s along n, ds = s', 1 / d = inv_d) at levers ro (other) and rt (tool)
  void add_stiffness(const Vec3& n, const Vec3& ro, const Vec3& rt, const Vec3& ro_n, double s, double ds,
                     double inv_d) {
    const double b = s * inv_d;
    const double a = ds - b;
    const Vec3 n_rt = cross(n, rt);
    const Vec3 an = a * n;
    const Vec3 a_ro_n = a * ro_n;
    for (int r = 0; r < 3; ++r) {
      const double anr = component(an, r), arnr = component(a_ro_n, r), rtr = b * component(rt, r);
      for (int c = 0; c < 3; ++c) {
        sum_p.a[r][c] += anr * component(n, c);
        sum_q.a[r][c] += anr * component(n_rt, c);
        sum_u.a[r][c] += arnr * component(n, c);
        sum_v.a[r][c] += arnr * component(n_rt, c);
        sum_w.a[r][c] += rtr * component(ro, c);
      }
    }
    sum_b += b;
    sum_bw += b * dot(ro, rt);
    sum_r += b * rt;
    sum_ro += b * ro;
  }

  // the model's S from the sums and its force F
  void assemble_stiffness(WrenchModel& m) {
    for (int i = 0; i < 3; ++i) {
      sum_p.a[i][i] += sum_b;
      sum_v.a[i][i] -= sum_bw;
    }
    const M3 skew_r = skew(sum_r);
    const M3 skew_ro = skew(sum_ro);
    const M3 skew_f = skew(m.wrench.force);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        m.stiffness[r][c] = sum_p.a[r][c];
        m.stiffness[r][c + 3] = -(sum_q.a[r][c] + skew_r.a[r][c]);
        m.stiffness[r + 3][c] = skew_f.a[r][c] + sum_u.a[r][c] + skew_ro.a[r][c];
        m.stiffness[r + 3][c + 3] = -(sum_v.a[r][c] + sum_w.a[r][c]);
      }
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < r; ++c) volume_jj[r][c] = volume_jj[c][r];
  }
};

// A frame's pairs seen from the tool: what every pair's contribution needs.
struct PairFrame {
  bool tool_is_b = true;
  Pose world_from_tool{};
  Pose world_from_other{};
  Mat3 rot_tool{};
  Mat3 rot_other{};
  double normal_sign = 1.0;  // Collette's normals run from a to b
  Vec3 center_of_mass{};
  bool gradient = false;
  bool damped = false;
  double per_area = 0.0;    // the gradient law's push per overlap area
  double per_volume = 0.0;  // the volume law's push per overlap volume
};

Vec3 place(const Mat3& r, const Vec3& t, const Sphere& sp) {
  const double x = static_cast<double>(sp.x), y = static_cast<double>(sp.y), z = static_cast<double>(sp.z);
  return Vec3{r.m[0][0] * x + r.m[0][1] * y + r.m[0][2] * z + t.x, r.m[1][0] * x + r.m[1][1] * y + r.m[1][2] * z + t.y,
              r.m[2][0] * x + r.m[2][1] * y + r.m[2][2] * z + t.z};
}

// Adds pair `p` to the model's wrench and volume gradient and to the sums (the selected pairs;
// every overlapping pair counts towards the damping's volume).
void add_pair(const SpherePairContact& p, const PairFrame& f, const PatchSelection& selection, WrenchModel& m,
              PairSums& sums) {
  const Sphere& so = f.tool_is_b ? p.sphere_a_local : p.sphere_b_local;
  const Sphere& st = f.tool_is_b ? p.sphere_b_local : p.sphere_a_local;
  const Vec3 co = place(f.rot_other, f.world_from_other.position, so);
  const Vec3 ct = place(f.rot_tool, f.world_from_tool.position, st);
  const double r_other = static_cast<double>(so.radius);
  const double r_tool = static_cast<double>(st.radius);
  const Vec3 delta = ct - co;
  const double d = norm(delta);
  const SphereOverlap<double> o = sphere_overlap(d, r_other, r_tool);
  if (!(o.volume > 0.0) || !std::isfinite(o.volume)) return;
  sums.all_volume += o.volume;
  if (!selection.includes(p)) return;
  ++m.pair_count;
  sums.total += o.volume;
  // coincident centres leave the centre line to the query's normal, and no sideways stiffness
  const bool has_line = d > 1e-6 * (r_other + r_tool);
  const double inv_d = has_line ? 1.0 / d : 0.0;
  const Vec3 n = has_line ? inv_d * delta
                          : f.normal_sign * Vec3{static_cast<double>(p.normal_world[0]),
                                                 static_cast<double>(p.normal_world[1]),
                                                 static_cast<double>(p.normal_world[2])};
  sums.volume_moment += o.volume * (co + o.centroid_offset * n);
  m.volume_gradient_world -= o.area * n;
  const Vec3 ro = co - f.center_of_mass;
  const Vec3 rt = ct - f.center_of_mass;
  const Vec3 ro_n = cross(ro, n);
  if (f.damped) {
    const double j[6] = {n.x, n.y, n.z, ro_n.x, ro_n.y, ro_n.z};
    for (int r = 0; r < 6; ++r)
      for (int c = r; c < 6; ++c) sums.volume_jj[r][c] += o.volume * j[r] * j[c];
  }
  sums.plain_radius += std::min(r_other, r_tool);
  sums.plain_lever2 += squared_norm(rt);
  const double s = f.gradient ? f.per_area * o.area : f.per_volume * o.volume;
  if (!(s > 0.0)) return;  // containment under the gradient law: no area, no push

  const double ds = f.gradient ? f.per_area * area_derivative(d, inv_d, r_other, r_tool) : -f.per_volume * o.area;
  const Vec3 push = s * n;
  m.wrench.force += push;
  m.wrench.torque += cross(ro, push);
  sums.add_stiffness(n, ro, rt, ro_n, s, ds, inv_d);
  sums.weight += s;
  sums.weighted_radius += s * std::min(r_other, r_tool);
  sums.weighted_lever2 += s * squared_norm(rt);
}

// The trust region: a fraction of the pushing spheres' radius, and the rotation that moves the
// mean lever that far (both weighted by push where there is any).
void set_trust_region(WrenchModel& m, const PairSums& sums, const WrenchModelOptions& options) {
  const double count = static_cast<double>(m.pair_count);
  const double radius = sums.weight > 0.0 ? sums.weighted_radius / sums.weight : sums.plain_radius / count;
  const double lever =
      std::sqrt(sums.weight > 0.0 ? sums.weighted_lever2 / sums.weight : sums.plain_lever2 / count);
  m.trust_translation = std::max(options.trust_fraction, 1e-6) * radius;
  m.trust_rotation = m.trust_translation / std::max(lever, radius);
}

}  // namespace

WrenchModel build_wrench_model(std::span<const SpherePairContact> pairs, const Pose& world_from_a,
                               const Pose& world_from_b, const PenaltyInput& input,
                               const WrenchModelOptions& options, const PatchSelection& selection) {
  WrenchModel m;
  PairFrame f;
  f.tool_is_b = input.tool_side == ContactSide::kB;
  f.world_from_tool = f.tool_is_b ? world_from_b : world_from_a;
  f.world_from_other = f.tool_is_b ? world_from_a : world_from_b;
  f.rot_tool = rotation_matrix(f.world_from_tool.rotation);
  f.rot_other = rotation_matrix(f.world_from_other.rotation);
  f.normal_sign = f.tool_is_b ? 1.0 : -1.0;
  f.center_of_mass = input.tool.center_of_mass_world;
  f.gradient = input.law == ForceLaw::kGradient;
  f.damped = input.damping > 0.0;
  const double calibration = f.gradient ? coverage_product(input) : 1.0;
  f.per_area = input.stiffness / calibration;
  f.per_volume = input.force_scale;
  m.six_dof = input.mode == ForceMode::k6Dof;
  m.tool_rotation = f.world_from_tool.rotation;
  m.center_of_mass_world = f.center_of_mass;
  m.world_from_tool = f.world_from_tool;
  m.world_from_other = f.world_from_other;

  PairSums sums;
  for (const SpherePairContact& p : pairs) add_pair(p, f, selection, m, sums);
  sums.assemble_stiffness(m);
  m.total_volume = sums.total;
  if (m.pair_count == 0) return m;  // nothing overlaps: the zero wrench
  m.contact = true;
  m.volume_centroid_world = (1.0 / sums.total) * sums.volume_moment;

  const double damping_scale = input.damping / std::max(sums.all_volume, damping_full_volume(input) * calibration);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m.damping[r][c] = damping_scale * sums.volume_jj[r][c];
  set_trust_region(m, sums, options);

  if (!m.six_dof) {
    m.wrench.torque = {};
    for (int r = 3; r < 6; ++r)
      for (int c = 0; c < 6; ++c) m.stiffness[r][c] = m.damping[r][c] = 0.0;
  }
  return m;
}

WrenchModel build_wrench_model(const ContactFrame& frame, const PenaltyInput& input,
                               const WrenchModelOptions& options) {
  WrenchModel m = build_wrench_model(frame.pairs(), frame.world_from_a, frame.world_from_b, input, options);
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
