#include "explorer_device.hpp"

#include <algorithm>
#include <cmath>

#include "contact.hpp"

namespace uh::exploration {
namespace {

constexpr double kFreeN = 0.02;  // below this the tool is free [N]
// a press begins at the first force felt at all: its depth is counted from the surface whatever
// the stiffness (at kTouchN a soft surface would already be further in than a stiff one)
constexpr double kFirstContactN = 1e-4;
constexpr double kForceGain = 0.015;  // normal force loop: speed per newton of error [m / (N s)]
constexpr double kNormalTauS = 0.02;  // low-pass of the normal estimate [s]
constexpr double kHoldS = 0.3;        // rest between strokes [s]
// the hand sits down to the stroke force, and lets go, within this time whatever the surface's
// spring: at the press speed, faster on a surface so soft that the press speed would take longer
// (through the proxy on a dome of k = 3e3 N/m^2, 0.19 N/mm: 10.6 mm to 2 N, 2.7 s each way at 4 mm/s)
constexpr double kSeatS = 0.5;
constexpr double kClearM = 0.002;     // lift this far past the last contact [m]
constexpr double kApproachSpeed = 0.01;  // [m/s]
constexpr double kMoveSpeed = 0.03;      // in the air between presses and strokes [m/s]
constexpr double kReturnSpeed = 0.02;    // back to the start [m/s]

// the level direction round the vertical line through `axis_point` at `p` (counter-clockwise seen from above)
Vec3 around_axis(const Vec3& p, const Vec3& axis_point) {
  return normalized(Vec3{-(p.y - axis_point.y), p.x - axis_point.x, 0.0});
}

}  // namespace

ExplorerDevice::ExplorerDevice(const haptico::SimDeviceOptions& device, const ExploreOptions& options,
                               const ExplorePlan& plan, double press_stop_n, std::size_t capacity)
    : SimulatedDevice("explorer", device),
      options_(options),
      plan_(plan),
      press_stop_n_(press_stop_n),
      position_(plan.start) {
  trace_.reserve(capacity);
}

haptico::DeviceState ExplorerDevice::sample(double) const {
  haptico::DeviceState s;
  s.position = position_;
  s.linear_velocity = velocity_;
  return s;
}

void ExplorerDevice::begin(ExplorePhase phase, double t) {
  phase_ = phase;
  phase_start_s_ = t;
  travelled_m_ = 0.0;
}

void ExplorerDevice::update_normal(const Vec3& force, const Vec3& along, double dt) {
  // the force without its component along the motion (friction) points along the normal
  const Vec3 pressing = force - dot(force, along) * along;
  if (norm(pressing) < kTouchN) return;
  normal_ = normalized(normal_ + std::min(1.0, dt / kNormalTauS) * (normalized(pressing) - normal_));
}

// moves along `direction` in the tangent plane at `speed` while holding `target` newtons of normal force
Vec3 ExplorerDevice::slide(const Vec3& force, const Vec3& direction, double speed, double target, double dt,
                           bool track_normal) {
  const Vec3 tangent = normalized(direction - dot(direction, normal_) * normal_);
  if (track_normal) update_normal(force, tangent, dt);
  const double pressing = dot(force, normal_);
  // a hand that lost the surface (it curved away) feels for it before going on, and one that ran
  // into a rise backs off first: it never slides through the object nor off into the air
  const bool lost = norm(force) < kTouchN, jammed = pressing > 2.5 * target;
  return (lost || jammed ? 0.0 : speed) * tangent - kForceGain * (target - pressing) * normal_;
}

void ExplorerDevice::integrate(double t, double dt, const haptico::DeviceCommand& cmd) {
  const Tick k{.t = t, .dt = dt, .f = cmd.force, .in_phase = t - phase_start_s_, .touching = norm(cmd.force)};
  if (trace_.size() < trace_.capacity())
    trace_.push_back({.time_s = t, .position = position_, .force = k.f, .phase = phase_, .leg = leg_});
  const Vec3 v = velocity_for(k);
  const Vec3 step = v * dt;
  position_ += step;
  velocity_ = v;
  travelled_m_ += norm(step);
  free_m_ += norm(step);
}

Vec3 ExplorerDevice::velocity_for(const Tick& k) {
  switch (phase_) {
    case ExplorePhase::kApproach: return approach(k);
    case ExplorePhase::kPress: return press(k);
    case ExplorePhase::kRelease: return release(k);
    case ExplorePhase::kMove: return move(k);
    case ExplorePhase::kSeat: return seat(k);
    case ExplorePhase::kHold: return hold(k);
    case ExplorePhase::kStroke: return stroke(k);
    case ExplorePhase::kContour: return contour(k);
    case ExplorePhase::kLift: return lift(k);
    case ExplorePhase::kTap: return tap(k);
    case ExplorePhase::kReturn: return go_back(k);
    case ExplorePhase::kDone: done(k); return {};
  }
  return {};
}

Vec3 ExplorerDevice::approach(const Tick& k) {
  const double felt = after_approach_ == ExplorePhase::kPress && options_.press_depth_m ? kFirstContactN : kTouchN;
  if (k.touching > felt) {
    touched_ = true;
    normal_ = normalized(k.f);
    touch_ = position_;
    begin(after_approach_, k.t);
  } else if (travelled_m_ > 0.03) {
    begin(ExplorePhase::kReturn, k.t);  // nothing there
  }
  return kApproachSpeed * plan_.approach;
}

Vec3 ExplorerDevice::press(const Tick& k) {
  update_normal(k.f, {}, k.dt);
  leg_ = press_;
  const Vec3 v = -options_.press_speed_m_per_s * normal_;
  const double depth = dot(touch_ - position_, normal_), pressing = dot(k.f, normal_);
  if (pressing >= press_stop_n_ || k.in_phase > 5.0 || (options_.press_depth_m && depth >= *options_.press_depth_m)) {
    if (depth > 0.0 && pressing > kTouchN) felt_n_per_m_ = pressing / depth;
    leg_ = -1;
    begin(ExplorePhase::kRelease, k.t);
  }
  return v;
}

Vec3 ExplorerDevice::release(const Tick& k) {
  // a press's release is read (the damping's loop, at the press's speed); a stroke's is not
  const bool after_press = after_approach_ == ExplorePhase::kPress;
  const Vec3 v = (after_press ? options_.press_speed_m_per_s : seat_speed()) * normal_;
  if (k.touching < kFreeN) next_after_release(k.t);
  if (k.in_phase > 5.0) begin(ExplorePhase::kReturn, k.t);
  return v;
}

// up to the level of the target first (never across the object), then across to it
Vec3 ExplorerDevice::move(const Tick& k) {
  const Vec3 to = move_to_ - position_;
  const double below = -dot(to, plan_.approach);
  Vec3 v{};
  if (below > 1e-9) {
    v = -kMoveSpeed * plan_.approach;
  } else if (norm(to) <= kMoveSpeed * k.dt) {
    v = to / k.dt;
    begin(ExplorePhase::kApproach, k.t);
  } else {
    v = to * (kMoveSpeed / norm(to));
  }
  if (k.in_phase > 5.0) begin(ExplorePhase::kReturn, k.t);
  return v;
}

// at the press speed, or faster where the presses felt a spring so soft that reaching the stroke
// force would take longer than kSeatS
double ExplorerDevice::seat_speed() const {
  const double to_stroke_force_m = felt_n_per_m_ > 0.0 ? options_.stroke_force_n / felt_n_per_m_ : 0.0;
  return std::max(options_.press_speed_m_per_s, to_stroke_force_m / kSeatS);
}

Vec3 ExplorerDevice::seat(const Tick& k) {
  update_normal(k.f, {}, k.dt);
  const Vec3 v = -seat_speed() * normal_;
  if (dot(k.f, normal_) >= options_.stroke_force_n) begin(ExplorePhase::kHold, k.t);
  if (k.in_phase > 5.0) begin(ExplorePhase::kReturn, k.t);
  return v;
}

// rests at the stroke force, then starts the next stroke, the contour, or lifts off
Vec3 ExplorerDevice::hold(const Tick& k) {
  const Vec3 v = -kForceGain * (options_.stroke_force_n - dot(k.f, normal_)) * normal_;
  if (k.in_phase < kHoldS) return v;
  if (next_leg_ < std::min(options_.stroke_legs, 4)) {
    leg_ = next_leg_++;
    leg_normal_ = normal_;
    begin(ExplorePhase::kStroke, k.t);
  } else if (!contour_done_ && options_.contour != ContourPath::kNone) {
    leg_ = -1;
    contour_turned_ = 0.0;
    contour_from_ = position_;
    begin(ExplorePhase::kContour, k.t);
  } else {
    leg_ = -1;
    begin(ExplorePhase::kLift, k.t);
  }
  return v;
}

Vec3 ExplorerDevice::stroke(const Tick& k) {
  const Vec3 direction = (leg_ % 2 == 0 ? 1.0 : -1.0) * plan_.axes[leg_ / 2];
  const Vec3 v = slide(k.f, direction, options_.stroke_speed_m_per_s, options_.stroke_force_n, k.dt, true);
  const bool edge =
      options_.stroke_stops_at_edge_rad && dot(normal_, leg_normal_) < std::cos(*options_.stroke_stops_at_edge_rad);
  if (travelled_m_ >= leg_length(options_, leg_) || edge) {
    leg_ = -1;
    begin(ExplorePhase::kRelease, k.t);  // lift off between strokes, as a finger does
  }
  return v;
}

Vec3 ExplorerDevice::contour(const Tick& k) {
  const double speed = options_.contour_speed_m_per_s.value_or(options_.stroke_speed_m_per_s);
  bool round = false;
  Vec3 v{};
  if (options_.contour == ContourPath::kAroundAxis) {
    // level round the centre line, holding the force's level part towards the line, as a finger
    // circles a vase (a normal taken from the force lags behind the turn and friction leans it
    // back, which steers a hand that slides across it outwards, off the surface)
    const Vec3 out = normalized(Vec3{position_.x - plan_.axis_point.x, position_.y - plan_.axis_point.y, 0.0});
    v = speed * around_axis(position_, plan_.axis_point) -
        kForceGain * (options_.stroke_force_n - dot(k.f, out)) * out;
    const Vec3 a = contour_from_ - plan_.axis_point, b = position_ + v * k.dt - plan_.axis_point;
    contour_turned_ += std::atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y);
    contour_from_ = position_ + v * k.dt;
    round = contour_turned_ >= 2.0 * kPi;
  } else {
    const double angle = speed * k.in_phase / options_.contour_radius_m;
    const Vec3 direction = std::cos(angle) * plan_.axes[0] + std::sin(angle) * plan_.axes[1];
    // on a circle the friction pulls across the motion too, which would tilt a normal taken from
    // the force: the hand keeps the normal it had when it sat down, the force loop does the rest
    v = slide(k.f, direction, speed, options_.stroke_force_n, k.dt, false);
    round = angle >= 2.0 * kPi;
  }
  if (round) {
    contour_done_ = true;
    begin(ExplorePhase::kLift, k.t);
  }
  return v;
}

Vec3 ExplorerDevice::lift(const Tick& k) {
  const Vec3 v = 2.0 * seat_speed() * normal_;
  if (k.touching > kFreeN) free_m_ = 0.0;
  if (k.in_phase > 5.0) begin(ExplorePhase::kReturn, k.t);
  if (free_m_ > kClearM) {
    tap_ = 0;
    tap_in_ = true;
    begin(ExplorePhase::kTap, k.t);
  }
  return v;
}

// in until the stroke force is felt, out until clear, `taps` times
Vec3 ExplorerDevice::tap(const Tick& k) {
  if (tap_ >= options_.taps) {
    begin(ExplorePhase::kReturn, k.t);
    return {};
  }
  if (tap_in_) {
    if (dot(k.f, normal_) >= options_.stroke_force_n || k.in_phase > 2.0) {
      tap_in_ = false;
      free_m_ = 0.0;
    }
    return -options_.tap_speed_m_per_s * normal_;
  }
  if (k.touching > kFreeN) free_m_ = 0.0;
  if (k.in_phase > 4.0) begin(ExplorePhase::kReturn, k.t);
  if (free_m_ > kClearM) {
    ++tap_;
    tap_in_ = true;
    phase_start_s_ = k.t;
  }
  return options_.tap_speed_m_per_s * normal_;
}

Vec3 ExplorerDevice::go_back(const Tick& k) {
  const Vec3 to_start = plan_.start - position_;
  const double left = norm(to_start);
  if (left <= kReturnSpeed * k.dt) {
    begin(ExplorePhase::kDone, k.t);
    return to_start / k.dt;
  }
  return to_start * (kReturnSpeed / left);
}

void ExplorerDevice::done(const Tick& k) {
  if (session_ != nullptr && k.in_phase > 0.05) session_->request_stop();
}

// where the hand goes after it came free: the next press, the start of the next pair of strokes,
// back to the site for the contour, or it sits down again where it is
void ExplorerDevice::next_after_release(double t) {
  const auto move_to = [&](const Vec3& to, ExplorePhase then) {
    move_to_ = to;
    after_approach_ = then;
    begin(ExplorePhase::kMove, t);
  };
  const int legs = std::min(options_.stroke_legs, 4);
  const bool through = options_.strokes_through_site;
  if (after_approach_ == ExplorePhase::kPress) {  // a press ended
    if (++press_ < options_.presses) {
      move_to(press_spot(plan_, options_, press_), ExplorePhase::kPress);
    } else if (through && legs > 0) {
      move_to(stroke_start(plan_, options_, 0), ExplorePhase::kSeat);
    } else if (options_.presses > 1) {
      move_to(plan_.start, ExplorePhase::kSeat);
    } else {
      after_approach_ = ExplorePhase::kSeat;
      begin(ExplorePhase::kSeat, t);
    }
    return;
  }
  if (through && next_leg_ > 0 && next_leg_ % 2 == 0) {  // a pair of strokes ended
    move_to(next_leg_ < legs ? stroke_start(plan_, options_, next_leg_) : plan_.start, ExplorePhase::kSeat);
    return;
  }
  begin(ExplorePhase::kSeat, t);
}

}  // namespace uh::exploration
