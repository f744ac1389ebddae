#pragma once
// The scripted explorer: a simulated hand that reads the force it is sent and moves the handle as a
// person exploring would (press until a force is felt, hold a normal force while stroking, follow a
// contour, tap), recording the trace the estimators read.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "plan.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/exploration/explore_trace.hpp"
#include "uh/haptico/simulated_device.hpp"

namespace uh::exploration {

// The simulated hand's own force limit [N]: above any tool's, so that the scene's tool and safety
// limits are the ones that bind (a press into a packed face to 2.5 mm under a 1 cm ball asks
// k pi (2 r d - d^2) times the fill there, 1.17: 40 N at k = 2.5e5 N/m^2)
constexpr double kExplorerMaxForceN = 100.0;

class ExplorerDevice final : public haptico::SimulatedDevice {
 public:
  ExplorerDevice(const haptico::SimDeviceOptions& device, const ExploreOptions& options, const ExplorePlan& plan,
                 double press_stop_n, std::size_t capacity);

  // the session the hand stops once the script is done
  void set_session(controllers::HapticSession* session) { session_ = session; }
  std::vector<ExploreSample>& trace() { return trace_; }
  bool touched() const { return touched_; }

 private:
  // what one tick of the script reads: the time, the force sent, how long the phase has lasted
  struct Tick {
    double t = 0.0;
    double dt = 0.0;
    Vec3 f{};
    double in_phase = 0.0;
    double touching = 0.0;  // |f|
  };

  haptico::DeviceState sample(double) const override;
  void integrate(double t, double dt, const haptico::DeviceCommand& cmd) override;

  // the hand's velocity in each phase of the script [m/s]; each may move on to the next phase
  Vec3 velocity_for(const Tick& k);
  Vec3 approach(const Tick& k);
  Vec3 press(const Tick& k);
  Vec3 release(const Tick& k);
  Vec3 move(const Tick& k);
  Vec3 seat(const Tick& k);
  Vec3 hold(const Tick& k);
  Vec3 stroke(const Tick& k);
  Vec3 contour(const Tick& k);
  Vec3 lift(const Tick& k);
  Vec3 tap(const Tick& k);
  Vec3 go_back(const Tick& k);
  void done(const Tick& k);

  void begin(ExplorePhase phase, double t);
  void update_normal(const Vec3& force, const Vec3& along, double dt);
  Vec3 slide(const Vec3& force, const Vec3& direction, double speed, double target, double dt, bool track_normal);
  void next_after_release(double t);
  double seat_speed() const;

  ExploreOptions options_;
  ExplorePlan plan_;
  double press_stop_n_;  // a press stops at this normal force [N]
  double felt_n_per_m_ = 0.0;  // the last press's force over its depth (0: none yet) [N/m]
  std::vector<ExploreSample> trace_;
  controllers::HapticSession* session_ = nullptr;
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

}  // namespace uh::exploration
