#include "uh/controllers/exploration.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

#include <fmt/format.h>

#include "uh/core/split_mix.hpp"
#include "uh/core/statistics.hpp"
#include "uh/haptico/device_registry.hpp"
#include "uh/haptico/simulated_device.hpp"

namespace uh::controllers {
namespace {

constexpr double kTouchN = 0.05;      // a force above this means contact [N]
constexpr double kFreeN = 0.02;       // below this the tool is free [N]
// a press begins at the first force felt at all: its depth is counted from the surface whatever
// the stiffness (at kTouchN a soft surface would already be further in than a stiff one)
constexpr double kFirstContactN = 1e-4;
constexpr double kForceGain = 0.015;  // normal force loop: speed per newton of error [m / (N s)]
constexpr double kNormalTauS = 0.02;  // low-pass of the normal estimate [s]
constexpr double kHoldS = 0.3;        // rest between strokes [s]
constexpr double kClearM = 0.002;     // lift this far past the last contact [m]
// the share of the contour's ripple a grating's plane wave must explain to count as periodic
constexpr double kPlaneWaveShare = 0.45;
// an axis whose strokes ripple less than this share of the other's may see the texture's slow component only
constexpr double kSlowAxisRipple = 0.6;
constexpr double kApproachSpeed = 0.01;  // [m/s]
constexpr double kMoveSpeed = 0.03;      // in the air between presses and strokes [m/s]
// The simulated hand's own force limit [N]: above any tool's, so that the scene's tool and safety
// limits are the ones that bind (a press into a packed face to 2.5 mm under a 1 cm ball asks
// k pi (2 r d - d^2) times the fill there, 1.17: 40 N at k = 2.5e5 N/m^2)
constexpr double kExplorerMaxForceN = 100.0;
// by default a press stops at this share of the force limit: the samples it fits are never clamped
constexpr double kPressShareOfLimit = 0.9;
// a sample whose force is within this share of the limit may have been clamped: the fit leaves it out
constexpr double kClampedShareOfLimit = 0.97;

// Where the hand starts, which way it goes in and how the strokes are turned (planned from the
// geometry before the run)
struct ExplorePlan {
  Vec3 start{};
  Vec3 approach{0, 0, -1};
  Vec3 axes[2]{};
  Vec3 axis_point{};  // on the footprint's vertical centre line
};

double leg_length(const ExploreOptions& o, std::int32_t leg) {
  return leg >= 2 ? o.second_stroke_length_m.value_or(o.stroke_length_m) : o.stroke_length_m;
}

// the level direction round the vertical line through `axis_point` at `p` (counter-clockwise seen from above)
Vec3 around_axis(const Vec3& p, const Vec3& axis_point) {
  return normalized(Vec3{-(p.y - axis_point.y), p.x - axis_point.x, 0.0});
}

// A hand that follows the exploration script: it reads the force it is sent and moves the handle
// as a person exploring would (press until a force is felt, hold a normal force while stroking).
class ExplorerDevice final : public haptico::SimulatedDevice {
 public:
  ExplorerDevice(const haptico::SimDeviceOptions& device, const ExploreOptions& options,
                 const ExplorePlan& plan, double press_stop_n, std::size_t capacity)
      : SimulatedDevice("explorer", device),
        options_(options),
        plan_(plan),
        press_stop_n_(press_stop_n),
        position_(plan.start) {
    trace_.reserve(capacity);
  }

  void set_session(HapticSession* session) { session_ = session; }
  std::vector<ExploreSample>& trace() { return trace_; }
  bool touched() const { return touched_; }

 private:
  haptico::DeviceState sample(double) const override {
    haptico::DeviceState s;
    s.position = position_;
    s.linear_velocity = velocity_;
    return s;
  }

  void begin(ExplorePhase phase, double t) {
    phase_ = phase;
    phase_start_s_ = t;
    travelled_m_ = 0.0;
  }

  void update_normal(const Vec3& force, const Vec3& along, double dt) {
    // the force without its component along the motion (friction) points along the normal
    const Vec3 pressing = force - dot(force, along) * along;
    if (norm(pressing) < kTouchN) return;
    normal_ = normalized(normal_ + std::min(1.0, dt / kNormalTauS) * (normalized(pressing) - normal_));
  }

  // moves along `direction` in the tangent plane at `speed` while holding `target` newtons of normal force
  Vec3 slide(const Vec3& force, const Vec3& direction, double speed, double target, double dt,
             bool track_normal) {
    const Vec3 tangent = normalized(direction - dot(direction, normal_) * normal_);
    if (track_normal) update_normal(force, tangent, dt);
    const double pressing = dot(force, normal_);
    // a hand that lost the surface (it curved away) feels for it before going on, and one that ran
    // into a rise backs off first: it never slides through the object nor off into the air
    const bool lost = norm(force)<kTouchN, jammed = pressing> 2.5 * target;
    return (lost || jammed ? 0.0 : speed) * tangent - kForceGain * (target - pressing) * normal_;
  }

  void integrate(double t, double dt, const haptico::DeviceCommand& cmd) override {
    const Vec3 f = cmd.force;
    if (trace_.size() < trace_.capacity())
      trace_.push_back({.time_s = t, .position = position_, .force = f, .phase = phase_, .leg = leg_});
    const double in_phase = t - phase_start_s_;
    const double touching = norm(f);
    Vec3 v{};
    switch (phase_) {
      case ExplorePhase::kApproach:
        v = kApproachSpeed * plan_.approach;
        if (touching >
            (after_approach_ == ExplorePhase::kPress && options_.press_depth_m ? kFirstContactN : kTouchN)) {
          touched_ = true;
          normal_ = normalized(f);
          touch_ = position_;
          begin(after_approach_, t);
        } else if (travelled_m_ > 0.03) {
          begin(ExplorePhase::kReturn, t);  // nothing there
        }
        break;
      case ExplorePhase::kPress:
        update_normal(f, {}, dt);
        leg_ = press_;
        v = -options_.press_speed_m_per_s * normal_;
        if (dot(f, normal_) >= press_stop_n_ || in_phase > 5.0 ||
            (options_.press_depth_m && dot(touch_ - position_, normal_) >= *options_.press_depth_m)) {
          leg_ = -1;
          begin(ExplorePhase::kRelease, t);
        }
        break;
      case ExplorePhase::kRelease:
        v = options_.press_speed_m_per_s * normal_;
        if (touching < kFreeN) next_after_release(t);
        if (in_phase > 5.0) begin(ExplorePhase::kReturn, t);
        break;
      case ExplorePhase::kMove: {
        // up to the level of the target first (never across the object), then across to it
        const Vec3 to = move_to_ - position_;
        const double below = -dot(to, plan_.approach);
        if (below > 1e-9) {
          v = -kMoveSpeed * plan_.approach;
        } else if (norm(to) <= kMoveSpeed * dt) {
          v = to / dt;
          begin(ExplorePhase::kApproach, t);
        } else {
          v = to * (kMoveSpeed / norm(to));
        }
        if (in_phase > 5.0) begin(ExplorePhase::kReturn, t);
        break;
      }
      case ExplorePhase::kSeat:
        update_normal(f, {}, dt);
        v = -options_.press_speed_m_per_s * normal_;
        if (dot(f, normal_) >= options_.stroke_force_n) begin(ExplorePhase::kHold, t);
        if (in_phase > 5.0) begin(ExplorePhase::kReturn, t);
        break;
      case ExplorePhase::kHold:
        v = -kForceGain * (options_.stroke_force_n - dot(f, normal_)) * normal_;
        if (in_phase >= kHoldS) {
          if (next_leg_ < std::min(options_.stroke_legs, 4)) {
            leg_ = next_leg_++;
            leg_normal_ = normal_;
            begin(ExplorePhase::kStroke, t);
          } else if (!contour_done_ && options_.contour != ContourPath::kNone) {
            leg_ = -1;
            contour_turned_ = 0.0;
            contour_from_ = position_;
            begin(ExplorePhase::kContour, t);
          } else {
            leg_ = -1;
            begin(ExplorePhase::kLift, t);
          }
        }
        break;
      case ExplorePhase::kStroke: {
        const Vec3 direction = (leg_ % 2 == 0 ? 1.0 : -1.0) * plan_.axes[leg_ / 2];
        v = slide(f, direction, options_.stroke_speed_m_per_s, options_.stroke_force_n, dt, true);
        const bool edge = options_.stroke_stops_at_edge_rad &&
                          dot(normal_, leg_normal_) < std::cos(*options_.stroke_stops_at_edge_rad);
        if (travelled_m_ >= leg_length(options_, leg_) || edge) {
          leg_ = -1;
          begin(ExplorePhase::kRelease, t);  // lift off between strokes, as a finger does
        }
        break;
      }
      case ExplorePhase::kContour: {
        const double speed = options_.contour_speed_m_per_s.value_or(options_.stroke_speed_m_per_s);
        bool round = false;
        if (options_.contour == ContourPath::kAroundAxis) {
          // level round the centre line, holding the force's level part towards the line, as a
          // finger circles a vase (a normal taken from the force lags behind the turn and friction
          // leans it back, which steers a hand that slides across it outwards, off the surface)
          const Vec3 out =
              normalized(Vec3{position_.x - plan_.axis_point.x, position_.y - plan_.axis_point.y, 0.0});
          v = speed * around_axis(position_, plan_.axis_point) -
              kForceGain * (options_.stroke_force_n - dot(f, out)) * out;
          const Vec3 a = contour_from_ - plan_.axis_point, b = position_ + v * dt - plan_.axis_point;
          contour_turned_ += std::atan2(a.x * b.y - a.y * b.x, a.x * b.x + a.y * b.y);
          contour_from_ = position_ + v * dt;
          round = contour_turned_ >= 2.0 * kPi;
        } else {
          const double angle = speed * in_phase / options_.contour_radius_m;
          const Vec3 direction = std::cos(angle) * plan_.axes[0] + std::sin(angle) * plan_.axes[1];
          // on a circle the friction pulls across the motion too, which would tilt a normal taken
          // from the force: the hand keeps the normal it had when it sat down, the force loop does the rest
          v = slide(f, direction, speed, options_.stroke_force_n, dt, false);
          round = angle >= 2.0 * kPi;
        }
        if (round) {
          contour_done_ = true;
          begin(ExplorePhase::kLift, t);
        }
        break;
      }
      case ExplorePhase::kLift:
        v = 2.0 * options_.press_speed_m_per_s * normal_;
        if (touching > kFreeN) free_m_ = 0.0;
        if (in_phase > 5.0) begin(ExplorePhase::kReturn, t);
        if (free_m_ > kClearM) {
          tap_ = 0;
          tap_in_ = true;
          begin(ExplorePhase::kTap, t);
        }
        break;
      case ExplorePhase::kTap:
        if (tap_ >= options_.taps) {
          begin(ExplorePhase::kReturn, t);
          break;
        }
        if (tap_in_) {
          v = -options_.tap_speed_m_per_s * normal_;
          if (dot(f, normal_) >= options_.stroke_force_n || in_phase > 2.0) {
            tap_in_ = false;
            free_m_ = 0.0;
          }
        } else {
          v = options_.tap_speed_m_per_s * normal_;
          if (touching > kFreeN) free_m_ = 0.0;
          if (in_phase > 4.0) begin(ExplorePhase::kReturn, t);
          if (free_m_ > kClearM) {
            ++tap_;
            tap_in_ = true;
            phase_start_s_ = t;
          }
        }
        break;
      case ExplorePhase::kReturn: {
        const Vec3 to_start = plan_.start - position_;
        const double left = norm(to_start);
        const double step = 0.02 * dt;
        if (left <= step) {
          v = to_start / dt;
          begin(ExplorePhase::kDone, t);
        } else {
          v = to_start * (0.02 / left);
        }
        break;
      }
      case ExplorePhase::kDone:
        if (session_ != nullptr && in_phase > 0.05) session_->request_stop();
        break;
    }
    const Vec3 step = v * dt;
    position_ += step;
    velocity_ = v;
    travelled_m_ += norm(step);
    free_m_ += norm(step);
  }

  // where the hand goes after it came free: the next press, the start of the next pair of strokes,
  // back to the site for the contour, or it sits down again where it is
  void next_after_release(double t) {
    const auto move = [&](const Vec3& to, ExplorePhase then) {
      move_to_ = to;
      after_approach_ = then;
      begin(ExplorePhase::kMove, t);
    };
    const int legs = std::min(options_.stroke_legs, 4);
    const bool through = options_.strokes_through_site;
    if (after_approach_ == ExplorePhase::kPress) {  // a press ended
      if (++press_ < options_.presses) {
        const double angle = kPi / 4.0 + kPi / 2.0 * (press_ - 1);
        move(plan_.start + options_.press_spread_m *
                               (std::cos(angle) * plan_.axes[0] + std::sin(angle) * plan_.axes[1]),
             ExplorePhase::kPress);
      } else if (through && legs > 0) {
        move(stroke_start(0), ExplorePhase::kSeat);
      } else if (options_.presses > 1) {
        move(plan_.start, ExplorePhase::kSeat);
      } else {
        after_approach_ = ExplorePhase::kSeat;
        begin(ExplorePhase::kSeat, t);
      }
      return;
    }
    if (through && next_leg_ > 0 && next_leg_ % 2 == 0) {  // a pair of strokes ended
      move(next_leg_ < legs ? stroke_start(next_leg_) : plan_.start, ExplorePhase::kSeat);
      return;
    }
    begin(ExplorePhase::kSeat, t);
  }

  // half a stroke before the site along the pair's axis (strokes_through_site)
  Vec3 stroke_start(std::int32_t leg) const {
    return plan_.start - 0.5 * leg_length(options_, leg) * plan_.axes[leg / 2];
  }

  ExploreOptions options_;
  ExplorePlan plan_;
  double press_stop_n_;  // a press stops at this normal force [N]
  std::vector<ExploreSample> trace_;
  HapticSession* session_ = nullptr;
  Vec3 position_{};
  Vec3 velocity_{};
  Vec3 normal_{0, 0, 1};
  ExplorePhase phase_ = ExplorePhase::kApproach;
  double phase_start_s_ = 0.0;
  double travelled_m_ = 0.0;
  double free_m_ = 0.0;
  std::int32_t leg_ = -1;
  std::int32_t next_leg_ = 0;
  bool contour_done_ = false;
  Vec3 leg_normal_{0, 0, 1};     // the normal where the stroke began
  double contour_turned_ = 0.0;  // kAroundAxis: the angle gone round the centre line so far [rad]
  Vec3 contour_from_{};
  int tap_ = 0;
  bool tap_in_ = true;
  bool touched_ = false;
  int press_ = 0;                                       // which press (the site's is 0)
  ExplorePhase after_approach_ = ExplorePhase::kPress;  // what a touch on the way in starts
  Vec3 move_to_{};                                      // where kMove goes
  Vec3 touch_{};                                        // where the press began
};

// The start 3 mm off the object where the site says (the seed moves it by up to 3 mm across the
// approach), the approach direction and the stroke axes; from the packed shapes (geometry only,
// never the material)
Result<ExplorePlan> plan_exploration(const collette::SphereTree& object, const Pose& world_from_object,
                                     const collette::SphereTree& tool, const ExploreOptions& options) {
  const auto leaves = object.leaves();
  if (leaves.empty()) return Error{"the object has no spheres"};
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  std::vector<std::pair<Vec3, double>> world;
  for (const Sphere& s : leaves) {
    const Vec3 c = transform_point(world_from_object, Vec3{static_cast<double>(s.x), static_cast<double>(s.y),
                                                            static_cast<double>(s.z)});
    const double r = static_cast<double>(s.radius);
    world.emplace_back(c, r);
    lo = {std::min(lo.x, c.x - r), std::min(lo.y, c.y - r), std::min(lo.z, c.z - r)};
    hi = {std::max(hi.x, c.x + r), std::max(hi.y, c.y + r), std::max(hi.z, c.z + r)};
  }
  core::SplitMix64 rng{options.seed};  // the seed's choices, the same run on every platform
  const double jitter_a = (rng.uniform() - 0.5) * 0.006, jitter_b = (rng.uniform() - 0.5) * 0.006;
  const double turn = options.stroke_turn_rad.value_or(2.0 * kPi * rng.uniform());
  const Vec3 middle{0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), lo.z};
  ExplorePlan plan;
  plan.axis_point = middle;
  // the tool's point that meets the object first, going in along `approach` (the handle holds
  // the tool upright: device frame = world)
  const auto tool_tip = [&tool](const Vec3& approach) {
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
  };
  if (options.site.from == ExploreSite::From::kTop) {
    const Vec3 target{middle.x + options.site.offset_m[0] + jitter_a,
                      middle.y + options.site.offset_m[1] + jitter_b, 0.0};
    double top = -1e300;
    for (const auto& [c, r] : world) {
      const double d2 = (c.x - target.x) * (c.x - target.x) + (c.y - target.y) * (c.y - target.y);
      if (d2 < r * r) top = std::max(top, c.z + std::sqrt(r * r - d2));
    }
    if (top < -1e299) top = hi.z;
    plan.approach = {0, 0, -1};
    const Vec3 tip = tool_tip(plan.approach);
    plan.start = Vec3{target.x - tip.x, target.y - tip.y, top + 0.003 - tip.z};
    plan.axes[0] = {std::cos(turn), std::sin(turn), 0.0};
    plan.axes[1] = {-std::sin(turn), std::cos(turn), 0.0};
    return plan;
  }
  // side: level towards the centre line from `azimuth`, at the height (both moved by the seed)
  const double azimuth = options.site.azimuth_rad + jitter_a / 0.05;  // up to 3 mm along a 5 cm radius
  const Vec3 out{std::cos(azimuth), std::sin(azimuth), 0.0};
  // (up or down by a third of the seed's move: a band round a coin's edge is a few millimetres high)
  const double z = lo.z + std::clamp(options.site.height_fraction, 0.0, 1.0) * (hi.z - lo.z) + jitter_b / 3.0;
  // the outermost surface point on the level ray from the centre line: per sphere, the circle it
  // cuts at height z, crossed by the ray
  double outer = -1e300;
  for (const auto& [c, r] : world) {
    const double dz = c.z - z;
    if (std::fabs(dz) >= r) continue;
    const double rho2 = r * r - dz * dz;
    const Vec3 rel{c.x - middle.x, c.y - middle.y, 0.0};
    const double along = dot(rel, out);
    const double across2 = dot(rel, rel) - along * along;
    if (across2 < rho2) outer = std::max(outer, along + std::sqrt(rho2 - across2));
  }
  if (outer < -1e299) return Error{fmt::format("nothing of the object is at height {:.4f} m", z)};
  plan.approach = -out;
  const Vec3 tip = tool_tip(plan.approach);
  const Vec3 surface{middle.x + outer * out.x, middle.y + outer * out.y, z};
  plan.start = surface + 0.003 * out - tip;
  plan.axes[0] = {0, 0, 1};
  plan.axes[1] = {-out.y, out.x, 0.0};
  return plan;
}

// ---- estimators: the trace alone ----

struct Line {
  double slope = 0.0;
  double intercept = 0.0;
};

Line fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  const double slope = sxx > 0.0 ? sxy / sxx : 0.0;
  return {slope, my - slope * mx};
}

// The slope of the least-squares parabola through (s, f) where it reaches zero force below the
// data (the first touch); the straight line's slope when the parabola has no such root.
double touch_slope(const std::vector<double>& s, const std::vector<double>& f) {
  const std::size_t n = s.size();
  const double s_mean = std::accumulate(s.begin(), s.end(), 0.0) / static_cast<double>(n);
  // normal equations in the centred variable u = s - mean (well conditioned)
  double m[3][4] = {};
  for (std::size_t i = 0; i < n; ++i) {
    const double u = s[i] - s_mean;
    const double p[3] = {1.0, u, u * u};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[r][c] += p[r] * p[c];
      m[r][3] += p[r] * f[i];
    }
  }
  for (int col = 0; col < 3; ++col) {  // Gauss-Jordan with partial pivoting
    int pivot = col;
    for (int r = col + 1; r < 3; ++r)
      if (std::fabs(m[r][col]) > std::fabs(m[pivot][col])) pivot = r;
    for (int c = 0; c < 4; ++c) std::swap(m[col][c], m[pivot][c]);
    if (m[col][col] == 0.0) return fit_line(s, f).slope;
    for (int r = 0; r < 3; ++r) {
      if (r == col) continue;
      const double q = m[r][col] / m[col][col];
      for (int c = 0; c < 4; ++c) m[r][c] -= q * m[col][c];
    }
  }
  const double c0 = m[0][3] / m[0][0], c1 = m[1][3] / m[1][1], c2 = m[2][3] / m[2][2];
  const double u_lo = *std::min_element(s.begin(), s.end()) - s_mean;
  // the root of c0 + c1 u + c2 u^2 nearest below the shallowest sample
  double root = 0.0;
  if (std::fabs(c2) < 1e-12 * std::fabs(c1)) {
    root = -c0 / c1;
  } else {
    const double disc = c1 * c1 - 4.0 * c2 * c0;
    if (disc < 0.0) return fit_line(s, f).slope;
    const double r1 = (-c1 - std::sqrt(disc)) / (2.0 * c2), r2 = (-c1 + std::sqrt(disc)) / (2.0 * c2);
    const bool ok1 = r1 <= u_lo, ok2 = r2 <= u_lo;
    if (!ok1 && !ok2) return fit_line(s, f).slope;
    root = ok1 && ok2 ? std::max(r1, r2) : (ok1 ? r1 : r2);
  }
  const double slope = c1 + 2.0 * c2 * root;
  return slope > 0.0 ? slope : fit_line(s, f).slope;
}

// The samples of one sliding stretch with, for each, the distance travelled, the motion
// direction (over about a millimetre of path) and the force split into normal and tangential parts
struct Slide {
  std::vector<double> time;
  std::vector<double> travel;
  std::vector<double> normal_n;
  std::vector<double> friction_ratio;
  std::vector<Vec3> position;
};

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
  }
  return s;
}

// Power of the detrended, Hann-windowed signal y(s) (uniformly resampled) at spatial frequency f [1/m]
struct Spectrum {
  std::vector<double> frequency;
  std::vector<double> power;
};

// `grid` resampled residuals over a common length; adds the power at each frequency
void add_spectrum(const std::vector<double>& residual, double ds, Spectrum& spectrum) {
  const std::size_t n = residual.size();
  for (std::size_t k = 0; k < spectrum.frequency.size(); ++k) {
    double re = 0.0, im = 0.0;
    const double w = 2.0 * kPi * spectrum.frequency[k] * ds;
    for (std::size_t i = 0; i < n; ++i) {
      const double hann =
          0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(i) / static_cast<double>(n - 1));
      re += hann * residual[i] * std::cos(w * static_cast<double>(i));
      im += hann * residual[i] * std::sin(w * static_cast<double>(i));
    }
    spectrum.power[k] += re * re + im * im;
  }
}

// The normal force over the sliding part of a stroke, resampled every `ds` metres, minus its line
std::vector<double> ripple_of(const Slide& s, double from_m, double to_m, double ds) {
  std::vector<double> out;
  std::size_t j = 0;
  for (double at = from_m; at <= to_m; at += ds) {
    while (j + 1 < s.travel.size() && s.travel[j + 1] < at) ++j;
    if (j + 1 >= s.travel.size()) break;
    const double span = s.travel[j + 1] - s.travel[j];
    const double u = span > 0.0 ? std::clamp((at - s.travel[j]) / span, 0.0, 1.0) : 0.0;
    out.push_back(s.normal_n[j] + u * (s.normal_n[j + 1] - s.normal_n[j]));
  }
  if (out.size() < 16) return {};
  // minus the least-squares cubic: what the hand's force loop and the shape's curvature add
  // varies over the whole stroke, the texture over millimetres
  constexpr int kTerms = 4;
  double m[kTerms][kTerms + 1] = {};
  const double half = 0.5 * static_cast<double>(out.size() - 1);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double u = (static_cast<double>(i) - half) / half;  // in [-1, 1]
    double p[kTerms] = {1.0, u, u * u, u * u * u};
    for (int r = 0; r < kTerms; ++r) {
      for (int c = 0; c < kTerms; ++c) m[r][c] += p[r] * p[c];
      m[r][kTerms] += p[r] * out[i];
    }
  }
  for (int col = 0; col < kTerms; ++col) {
    int pivot = col;
    for (int r = col + 1; r < kTerms; ++r)
      if (std::fabs(m[r][col]) > std::fabs(m[pivot][col])) pivot = r;
    for (int c = 0; c <= kTerms; ++c) std::swap(m[col][c], m[pivot][c]);
    if (m[col][col] == 0.0) return {};
    for (int r = 0; r < kTerms; ++r) {
      if (r == col) continue;
      const double q = m[r][col] / m[col][col];
      for (int c = 0; c <= kTerms; ++c) m[r][c] -= q * m[col][c];
    }
  }
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double u = (static_cast<double>(i) - half) / half;
    out[i] -= m[0][kTerms] / m[0][0] +
              u * (m[1][kTerms] / m[1][1] + u * (m[2][kTerms] / m[2][2] + u * m[3][kTerms] / m[3][3]));
  }
  return out;
}

// Least squares: the coefficients c minimising sum_i (y_i - sum_k c_k basis_i[k])^2 and the
// residual sum of squares; empty when the columns are degenerate
struct LeastSquares {
  std::vector<double> coefficients;
  double residual = 0.0;
};

LeastSquares least_squares(const std::vector<std::vector<double>>& basis, const std::vector<double>& y) {
  LeastSquares out;
  if (basis.empty()) return out;
  const std::size_t n = basis.front().size();
  std::vector<double> m(n * (n + 1), 0.0);  // the normal equations, augmented, row-major
  for (std::size_t i = 0; i < basis.size(); ++i)
    for (std::size_t r = 0; r < n; ++r) {
      for (std::size_t c = 0; c < n; ++c) m[r * (n + 1) + c] += basis[i][r] * basis[i][c];
      m[r * (n + 1) + n] += basis[i][r] * y[i];
    }
  for (std::size_t col = 0; col < n; ++col) {  // Gauss-Jordan with partial pivoting
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < n; ++r)
      if (std::fabs(m[r * (n + 1) + col]) > std::fabs(m[pivot * (n + 1) + col])) pivot = r;
    for (std::size_t c = 0; c <= n; ++c) std::swap(m[col * (n + 1) + c], m[pivot * (n + 1) + c]);
    if (!(std::fabs(m[col * (n + 1) + col]) > 0.0)) return out;
    for (std::size_t r = 0; r < n; ++r) {
      if (r == col) continue;
      const double q = m[r * (n + 1) + col] / m[col * (n + 1) + col];
      for (std::size_t c = 0; c <= n; ++c) m[r * (n + 1) + c] -= q * m[col * (n + 1) + c];
    }
  }
  out.coefficients.resize(n);
  for (std::size_t r = 0; r < n; ++r) out.coefficients[r] = m[r * (n + 1) + n] / m[r * (n + 1) + r];
  for (std::size_t i = 0; i < basis.size(); ++i) {
    double fitted = 0.0;
    for (std::size_t k = 0; k < n; ++k) fitted += out.coefficients[k] * basis[i][k];
    out.residual += (y[i] - fitted) * (y[i] - fitted);
  }
  return out;
}

// The damping of one loop into a surface and out again (samples [first, end) in contact): the
// normal force over its deeper part (60 % to 95 % of its depth past first touch: past a penalty's
// damping ramp, tool.force.damping_full_volume, for a 1 cm ball pressed 2.5 mm in) fitted by least squares as
// c0 + c1 s + c2 s^2 + b v: the curve of depth s that the way in and the way out share, and b times
// the speed into the surface v (central differences of the positions; + in, - out), which opens the
// loop between them. Samples near the turn (slower than half the median speed) say nothing of b
// and are left out; both directions must have samples. Empty without enough evidence.
std::optional<double> loop_damping(const std::vector<ExploreSample>& x, std::size_t first, std::size_t end) {
  if (first == 0 || end >= x.size() || end - first < 12) return std::nullopt;  // neighbours for the speed
  double f_max = 0.0;
  for (std::size_t k = first; k < end; ++k) f_max = std::max(f_max, norm(x[k].force));
  Vec3 sum{};
  for (std::size_t k = first; k < end; ++k)
    if (norm(x[k].force) > 0.2 * f_max) sum += x[k].force;
  const Vec3 n = normalized(sum);
  const double touch = -dot(x[first].position, n);
  double reach = 0.0;
  for (std::size_t k = first; k < end; ++k) reach = std::max(reach, -dot(x[k].position, n) - touch);
  if (!(reach > 0.0)) return std::nullopt;
  std::vector<double> speed(end - first), magnitude(end - first);
  for (std::size_t k = first; k < end; ++k) {
    const double dt = x[k + 1].time_s - x[k - 1].time_s;
    speed[k - first] = dt > 0.0 ? -dot(x[k + 1].position - x[k - 1].position, n) / dt : 0.0;
    magnitude[k - first] = std::fabs(speed[k - first]);
  }
  const double typical = core::median(magnitude);
  if (!(typical > 0.0)) return std::nullopt;
  std::vector<std::vector<double>> basis;
  std::vector<double> force;
  int in = 0, out = 0;
  for (std::size_t k = first; k < end; ++k) {
    const double depth = -dot(x[k].position, n) - touch, v = speed[k - first];
    if (depth < 0.6 * reach || depth > 0.95 * reach || std::fabs(v) < 0.5 * typical) continue;
    // depth in units of the reach and speed in units of the typical speed: columns of one size, so
    // the normal equations stay well conditioned
    const double u = depth / reach;
    basis.push_back({1.0, u, u * u, v / typical});
    force.push_back(dot(x[k].force, n));
    (v > 0.0 ? in : out) += 1;
  }
  if (in < 4 || out < 4) return std::nullopt;
  const LeastSquares fit = least_squares(basis, force);
  if (fit.coefficients.size() != 4) return std::nullopt;
  return fit.coefficients[3] / typical;
}

// How much of the ripple of the normal force along the contour one plane wave explains
struct PlaneWaveFit {
  double share = 0.0;         ///< of the ripple's power (after the circle's slow variation) [0, 1]
  double f1 = 0.0, f2 = 0.0;  ///< the wave vector's spatial frequencies along e1, e2 [1/m]
};

// The candidates are the strokes' frequencies with either relative sign (a stroke sees |k . e|
// only); an axis without a peak (its apparent period too long for a stroke) has its component
// searched below the strokes' lowest frequency `f_low`
//
// The hand holds its force with a loop that follows slow bumps, so part of a texture shows in the
// hand's height rather than in the force: the ripple fitted is the force plus the contact's
// stiffness `stiffness` [N/m] times the hand's height along the normal (what the force would have
// been had the hand not moved), averaged over a quarter millimetre (the passivity controller's
// tick-to-tick cuts are no texture).
//
// The search trusts an axis only when the other axis's strokes ripple clearly less (a slow
// component is mostly taken out with the strokes' drift; a random texture ripples alike along
// both axes, and searching its contour would find some wave that fits by chance).
PlaneWaveFit fit_plane_wave(const Slide& contour, const Vec3 (&axes)[2], const double (&f)[2], double f_low,
                            double stiffness, const double (&ripple)[2]) {
  PlaneWaveFit best;
  const std::size_t n = contour.position.size();
  if (n < 32) return best;
  const double circle = contour.travel.back();
  Vec3 centre{};
  for (const Vec3& p : contour.position) centre += p;
  centre = centre / static_cast<double>(n);
  Vec3 normal = cross(axes[0], axes[1]);
  if (normal.z < 0.0) normal = -1.0 * normal;
  std::vector<double> unmoved(n);
  for (std::size_t j = 0; j < n; ++j)
    unmoved[j] = contour.normal_n[j] + stiffness * dot(contour.position[j] - centre, normal);
  std::vector<double> smooth(n);
  for (std::size_t j = 0, a = 0, b = 0; j < n; ++j) {
    while (contour.travel[j] - contour.travel[a] > 1.25e-4) ++a;
    while (b + 1 < n && contour.travel[b + 1] - contour.travel[j] <= 1.25e-4) ++b;
    smooth[j] = std::accumulate(unmoved.begin() + static_cast<std::ptrdiff_t>(a),
                                unmoved.begin() + static_cast<std::ptrdiff_t>(b) + 1, 0.0) /
                static_cast<double>(b - a + 1);
  }
  // the slow part: the shape and the force loop vary once or twice per turn and drift along it
  std::vector<std::vector<double>> slow;
  std::vector<double> y, u1, u2;
  for (std::size_t j = 0; j < n; ++j) {
    if (contour.travel[j] < 0.1 * circle) continue;  // the seat's transient
    const Vec3 d = contour.position[j] - centre;
    const double a = dot(d, axes[0]), b = dot(d, axes[1]), theta = std::atan2(b, a);
    slow.push_back({1.0, std::cos(theta), std::sin(theta), std::cos(2.0 * theta), std::sin(2.0 * theta),
                    contour.travel[j] / circle});
    y.push_back(smooth[j]);
    u1.push_back(a);
    u2.push_back(b);
  }
  const LeastSquares base = least_squares(slow, y);
  if (base.coefficients.empty() || !(base.residual > 0.0)) return best;
  const auto share_of = [&](double g1, double g2) {
    std::vector<std::vector<double>> basis = slow;
    for (std::size_t i = 0; i < basis.size(); ++i) {
      const double phase = 2.0 * kPi * (g1 * u1[i] + g2 * u2[i]);
      basis[i].push_back(std::cos(phase));
      basis[i].push_back(std::sin(phase));
    }
    const LeastSquares full = least_squares(basis, y);
    return full.coefficients.empty() ? 0.0 : 1.0 - full.residual / base.residual;
  };
  const auto consider = [&](double g1, double g2) {
    const double share = share_of(g1, g2);
    if (share > best.share) best = {share, g1, g2};
  };
  if (f[0] > 0.0 && f[1] > 0.0) {
    consider(f[0], f[1]);
    consider(f[0], -f[1]);
  }
  // an axis may see no period because its apparent period is too long for a stroke (the
  // component lies within (-f_low, f_low)), and then show a packing's grain instead: with each
  // axis's frequency trusted alone, the other component is searched within (-f_low, f_low), in
  // steps that keep the phase error over the circle's radius under half a radian, then finer
  // around the best (a search over all frequencies would fit a random texture's contour by
  // chance: the best of a hundred candidates)
  const double radius = circle / (2.0 * kPi);
  const double step = 0.5 / (2.0 * kPi * radius);
  for (int axis = 0; axis < 2; ++axis) {
    if (!(f[axis] > 0.0) || !(ripple[1 - axis] <= kSlowAxisRipple * ripple[axis])) continue;
    const double reach = f_low;
    const auto at = [&](double g) { return axis == 0 ? std::pair{f[0], g} : std::pair{g, f[1]}; };
    PlaneWaveFit coarse;
    for (double g = -reach; g <= reach; g += step) {
      const auto [g1, g2] = at(g);
      const double share = share_of(g1, g2);
      if (share > coarse.share) coarse = {share, g1, g2};
    }
    const double found = axis == 0 ? coarse.f2 : coarse.f1;
    for (double g = found - step; g <= found + step; g += step / 8.0) {
      const auto [g1, g2] = at(g);
      consider(g1, g2);
    }
  }
  return best;
}

}  // namespace

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

double press_stop_force_n(const ExploreOptions& options, double force_limit_n) {
  return options.press_force_n.value_or(kPressShareOfLimit * force_limit_n);
}

MaterialEstimate estimate_material(const ExploreTrace& trace) {
  MaterialEstimate e;
  const ExploreOptions& o = trace.options;
  const auto& x = trace.samples;

  // stiffness: per press, normal force against depth while pressing in, fitted with
  // F = c0 + c1 s + c2 s^2 (a round contact stiffens or softens with depth: a ball on a plane is
  // exactly quadratic, k pi (2 r d - d^2)); the press's stiffness is the slope where the fit
  // reaches zero force, at first touch: for a round tip 2 pi r k. The fit takes the depths from 15 %
  // to 95 % of the press's (a press to a depth: the same depths for every material) or the forces
  // from 10 % to 95 % of the press force (a press to a force), without the samples near the force
  // limit (clamped: they read the limit, not the material). The estimate is the presses' median
  // (each also reads the packing's grain under the tip)
  {
    const double press_stop_n = press_stop_force_n(o, trace.force_limit_n);
    std::vector<double> reaches;
    std::int32_t presses = 0;
    for (const auto& s : x)
      if (s.phase == ExplorePhase::kPress) presses = std::max(presses, s.leg + 1);
    for (std::int32_t press = 0; press < std::max(presses, 1); ++press) {
      const auto in_press = [&](const ExploreSample& s) {
        return s.phase == ExplorePhase::kPress && (presses == 0 || s.leg == press);
      };
      Vec3 sum{};
      double f_max = 0.0;
      for (const auto& s : x)
        if (in_press(s)) f_max = std::max(f_max, norm(s.force));
      for (const auto& s : x)
        if (in_press(s) && norm(s.force) > 0.2 * f_max) sum += s.force;
      const Vec3 n = normalized(sum);
      double first = 0.0, deepest = -1e300;
      bool any = false;
      for (const auto& s : x)
        if (in_press(s)) {
          const double d = -dot(s.position, n);
          if (!any) first = d;
          any = true;
          deepest = std::max(deepest, d);
        }
      const double reach = deepest - first;
      if (any) reaches.push_back(reach);
      std::vector<double> depth, force;
      for (const auto& s : x) {
        if (!in_press(s)) continue;
        const double fn = dot(s.force, n), d = -dot(s.position, n);
        const bool in_band = o.press_depth_m ? d - first >= 0.15 * reach && d - first <= 0.95 * reach
                                             : fn >= 0.1 * press_stop_n && fn <= 0.95 * press_stop_n;
        const bool clamped = norm(s.force) >= kClampedShareOfLimit * trace.force_limit_n;
        if (!in_band || clamped || fn < 2.0 * kTouchN) continue;
        depth.push_back(d);
        force.push_back(fn);
      }
      if (depth.size() >= 10) e.stiffness_per_press_n_per_mm.push_back(touch_slope(depth, force) * 1e-3);
    }
    if (!e.stiffness_per_press_n_per_mm.empty())
      e.stiffness_n_per_mm = core::median(e.stiffness_per_press_n_per_mm);
    if (!reaches.empty()) e.press_reach_m = core::median(reaches);
  }

  // damping: per press, the loop between its way in and its release (loop_damping); the median of
  // the presses (a grating's heights under one press can open its loop: the median passes it over).
  // The presses, not the taps: they go 2.5 mm in, past any damping ramp at first touch, and the
  // grain of a packing reads the same on the way in and out at one spot, so it cancels in the loop
  const auto pressing = [](const ExploreSample& s) {
    return (s.phase == ExplorePhase::kPress || s.phase == ExplorePhase::kRelease) && norm(s.force) > kTouchN;
  };
  for (std::size_t i = 0; i < x.size();) {
    if (!pressing(x[i])) {
      ++i;
      continue;
    }
    const std::size_t first = i;
    while (i < x.size() && pressing(x[i])) ++i;
    if (const auto b = loop_damping(x, first, i)) e.damping_per_press_n_s_per_m.push_back(*b);
  }
  if (!e.damping_per_press_n_s_per_m.empty()) e.damping_n_s_per_m = core::median(e.damping_per_press_n_s_per_m);

  // friction: per stroke, the largest ratio before a third of the stroke (breakaway) and the
  // median ratio over its second half (sliding); the contour's median ratio joins the sliding ones
  std::vector<double> breakaway, sliding;
  Slide legs[4];
  for (int leg = 0; leg < 4; ++leg) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (x[i].phase == ExplorePhase::kStroke && x[i].leg == leg) idx.push_back(i);
    legs[leg] = slide_of(trace, idx);
    const Slide& s = legs[leg];
    if (s.travel.empty()) continue;
    // the breakaway: the largest force against the motion over the first third, over the median
    // force across it there (a texture ripples the force across the motion, not the friction the
    // stick point holds: a tick's own ratio would read the ripple's troughs)
    const double length = leg_length(o, leg);
    double peak = -1e300;
    std::vector<double> across, slid;
    for (std::size_t j = 0; j < s.travel.size(); ++j)
      if (s.travel[j] < length / 3.0) {
        peak = std::max(peak, s.friction_ratio[j] * s.normal_n[j]);
        across.push_back(s.normal_n[j]);
      }
    if (!across.empty()) peak /= core::median(across);
    for (std::size_t j = 0; j < s.travel.size(); ++j)
      if (s.travel[j] > 0.5 * length && s.travel[j] < 0.95 * length) slid.push_back(s.friction_ratio[j]);
    if (peak > -1e300) breakaway.push_back(peak);
    if (!slid.empty()) sliding.push_back(core::median(slid));
  }
  Slide contour;
  {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (x[i].phase == ExplorePhase::kContour) idx.push_back(i);
    contour = slide_of(trace, idx);
    const Slide& c = contour;
    std::vector<double> slid;
    const double circle = 2.0 * kPi * o.contour_radius_m;
    for (std::size_t j = 0; j < c.travel.size(); ++j)
      if (c.travel[j] > 0.25 * circle) slid.push_back(c.friction_ratio[j]);
    if (!slid.empty()) sliding.push_back(core::median(slid));
  }
  const auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  };
  if (!breakaway.empty()) e.friction_static = std::max(0.0, mean(breakaway));
  if (!sliding.empty()) e.friction_dynamic = std::max(0.0, mean(sliding));

  // texture: the spectrum of the normal force ripple along each stroke axis (both strokes of the
  // axis), after the breakaway (past 15 % of the stroke); the dominant spatial frequencies of the two axes
  // are the components of the texture's wave vector in the stroke plane, so period = 1 / |(f_1, f_2)|
  const double ds = 2.5e-5;  // resampling step [m]: 40 samples per millimetre
  double sum_sq = 0.0;
  std::size_t count = 0;
  double axis_frequency[2] = {0.0, 0.0};  // [1/m], 0 = no peak along that axis
  for (int axis = 0; axis < 2; ++axis) {
    const double from = 0.15 * leg_length(o, 2 * axis), to = 0.97 * leg_length(o, 2 * axis);
    Spectrum spectrum;
    const double span = to - from;
    for (double f = 2.0 / span; f <= 1.0 / (8.0 * ds); f += 1.0 / (16.0 * span))
      spectrum.frequency.push_back(f);
    spectrum.power.assign(spectrum.frequency.size(), 0.0);
    bool any = false;
    double axis_sq = 0.0;
    std::size_t axis_count = 0;
    for (int leg = 2 * axis; leg < 2 * axis + 2; ++leg) {
      const std::vector<double> r = ripple_of(legs[leg], from, to, ds);
      if (r.empty()) continue;
      any = true;
      for (double v : r) axis_sq += v * v;
      axis_count += r.size();
      add_spectrum(r, ds, spectrum);
    }
    sum_sq += axis_sq;
    if (axis_count > 0) e.ripple_axis_n[axis] = std::sqrt(axis_sq / static_cast<double>(axis_count));
    count += axis_count;
    // a ripple under 0.5 % of the stroke force is the hand's own wobble, not a texture
    if (axis_count == 0 || std::sqrt(axis_sq / static_cast<double>(axis_count)) < 0.005 * o.stroke_force_n)
      continue;
    if (!any || spectrum.power.size() < 3) continue;
    // the strongest local maximum with at least 2.5 periods in the window (slower variation
    // left over by the detrending leaks into the lowest frequencies and is no texture)
    std::size_t peak = 0;
    for (std::size_t k = 1; k + 1 < spectrum.power.size(); ++k) {
      if (spectrum.frequency[k] * span < 2.5) continue;
      if (spectrum.power[k] < spectrum.power[k - 1] || spectrum.power[k] < spectrum.power[k + 1]) continue;
      if (peak == 0 || spectrum.power[k] > spectrum.power[peak]) peak = k;
    }
    const double background = core::median(spectrum.power);
    // a texture stands out of the packing's own grain by an order of magnitude and more
    if (!(spectrum.power[peak] > 30.0 * background) || peak == 0 || peak + 1 >= spectrum.power.size())
      continue;
    // the peak between the grid points: a parabola through the three around it
    const double p0 = spectrum.power[peak - 1], p1 = spectrum.power[peak], p2 = spectrum.power[peak + 1];
    const double denom = p0 - 2.0 * p1 + p2;
    const double shift = denom != 0.0 ? 0.5 * (p0 - p2) / denom : 0.0;
    const double f = spectrum.frequency[peak] + shift * (spectrum.frequency[1] - spectrum.frequency[0]);
    e.period_axis_m[axis] = 1.0 / f;
    axis_frequency[axis] = f;
  }
  if (count > 0) e.texture_ripple_n = std::sqrt(sum_sq / static_cast<double>(count));
  if (axis_frequency[0] > 0.0 || axis_frequency[1] > 0.0) {
    // a grating is one plane wave over the whole surface: the wave vector the strokes found must
    // also explain the ripple along the contour, a third path; a random texture (or a packing's
    // grain) has its strongest component differ from path to path, and then has no period
    const PlaneWaveFit fit = fit_plane_wave(contour, trace.stroke_axes, axis_frequency, 2.5 / (0.82 * std::min(leg_length(o, 0), leg_length(o, 2))),
                                            e.stiffness_n_per_mm.value_or(0.0) * 1e3, e.ripple_axis_n);
    e.texture_wave_share = fit.share;
    if (fit.share >= kPlaneWaveShare) e.texture_period_m = 1.0 / std::hypot(fit.f1, fit.f2);
  }
  return e;
}

Result<std::vector<ObjectExploration>> explore_scene(const Scene& scene, const std::string& object_name,
                                                     const ExploreOptions& options,
                                                     const SessionOptions& session_options) {
  std::vector<ObjectExploration> out;
  const std::filesystem::path cache =
      session_options.cache_dir.empty() ? default_cache_dir() : session_options.cache_dir;
  const double haptic_hz = options.haptic_hz.value_or(session_options.haptic_hz.value_or(scene.haptic_hz));
  if (!(haptic_hz >= 1.0 && haptic_hz <= 10000.0))
    return Error{fmt::format("{}: haptic rate {} Hz is outside [1, 10000]", scene.source, haptic_hz)};
  bool found = object_name.empty();
  for (const SceneObject& object : scene.objects) {
    if (!object_name.empty() && object.name != object_name) continue;
    found = true;
    Scene alone = scene;
    alone.objects = {object};
    alone.watch = {object.name};
    alone.tools.resize(1);  // the first tool explores
    alone.tool().device = {.driver = "explorer", .config = {}};
    alone.tool().workspace = {};  // the device frame is the world frame

    auto object_tree = load_shape_tree(object.shape, cache, session_options.build_progress);
    if (!object_tree)
      return Error{
          fmt::format("{}: object '{}': {}", scene.source, object.name, object_tree.error().message)};
    auto tool_tree = load_shape_tree(scene.tool().shape, cache, session_options.build_progress);
    if (!tool_tree)
      return Error{
          fmt::format("{}: tool '{}': {}", scene.source, scene.tool().name, tool_tree.error().message)};
    auto plan = plan_exploration(*object_tree->tree, object.pose, *tool_tree->tree, options);
    if (!plan)
      return Error{fmt::format("{}: object '{}': {}", scene.source, object.name, plan.error().message)};
    alone.tool().shape.tree = tool_tree->tree;  // loaded once
    alone.tool().shape.coverage = tool_tree->coverage;
    alone.objects[0].shape.tree = object_tree->tree;
    alone.objects[0].shape.coverage = object_tree->coverage;

    const auto capacity = static_cast<std::size_t>(options.max_seconds * haptic_hz) + 16;
    // the smallest force limit of the session's chain (haptico::ForceLimiter): the hand's, the tool's, the
    // safety limit
    const double force_limit_n =
        std::min({kExplorerMaxForceN, alone.tool().force.max_force_n, alone.safety_limits.max_force_n});
    auto device = std::make_unique<ExplorerDevice>(
        haptico::SimDeviceOptions{.rate_hz = haptic_hz,
                                  .max_force_n = kExplorerMaxForceN,
                                  .dof_actuated = 3,
                                  .workspace_half_extents = {10.0, 10.0, 10.0}},
        options, *plan, press_stop_force_n(options, force_limit_n), capacity);
    ExplorerDevice* explorer = device.get();
    auto holder = std::make_shared<std::unique_ptr<haptico::HapticDevice>>(std::move(device));
    haptico::DeviceRegistry registry;
    if (auto r = registry.register_driver(
            "explorer",
            [holder](const haptico::DeviceConfig&) -> Result<std::unique_ptr<haptico::HapticDevice>> {
              if (!*holder) return Error{"the exploration's hand is used by one session only"};
              return std::move(*holder);
            });
        !r)
      return r.error();
    SessionOptions so = session_options;
    so.haptic_hz = haptic_hz;
    so.collision_hz = haptic_hz / options.ticks_per_collision_step;
    so.cache_dir = cache;
    auto session = HapticSession::create(alone, so, registry);
    if (!session) return session.error();
    explorer->set_session(session->get());
    if (auto ran = (*session)->run_stepped(options.max_seconds, options.ticks_per_collision_step); !ran)
      return ran.error();
    if (!explorer->touched())
      return Error{
          fmt::format("{}: object '{}': the tool never touched it on its way in", scene.source, object.name)};
    ObjectExploration result;
    result.object = object.name;
    result.trace.samples = std::move(explorer->trace());
    result.trace.options = options;
    result.trace.force_limit_n = force_limit_n;
    result.trace.stroke_axes[0] = plan->axes[0];
    result.trace.stroke_axes[1] = plan->axes[1];
    result.trace.axis_point = plan->axis_point;
    result.work_on_hand_j = (*session)->report().work_on_hand_j;
    result.simulated_s = (*session)->report().seconds;
    result.haptic_ticks = (*session)->report().haptic_ticks;
    result.estimate = estimate_material(result.trace);
    out.push_back(std::move(result));
  }
  if (!found) {
    std::string names;
    for (const auto& o : scene.objects) names += fmt::format("{}'{}'", names.empty() ? "" : ", ", o.name);
    return Error{
        fmt::format("{}: no object is named '{}' (the scene has {})", scene.source, object_name, names)};
  }
  return out;
}

}  // namespace uh::controllers
