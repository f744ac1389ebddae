#pragma once
/// \file
/// The museum's floor plan and the numbers of its rules: rooms, display cases, Phantom's table,
/// the guards' patrol routes, the artifact kinds on show, speeds, hearing radii and view cones.
///
/// A Level is immutable once made (like MuJoCo's mjModel): the rule step (rules.hpp) reads it and
/// the game state refers to its parts by index. The floor is the plane z = 0 seen from above,
/// x east and y north, in metres. Rooms are axis-aligned rectangles; the space between two rooms
/// is wall, and a doorway is a small room that overlaps both (the union of the rooms is the floor
/// anyone may stand on).

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "uh/core/result.hpp"

namespace uh::museum {

/// A point or a displacement on the floor [m] (frame: the level's, x east, y north).
struct Vec2 {
  double x = 0.0;
  double y = 0.0;

  constexpr Vec2& operator+=(const Vec2& o) {
    x += o.x;
    y += o.y;
    return *this;
  }
  constexpr Vec2& operator-=(const Vec2& o) {
    x -= o.x;
    y -= o.y;
    return *this;
  }
  friend constexpr Vec2 operator+(Vec2 a, const Vec2& b) { return a += b; }
  friend constexpr Vec2 operator-(Vec2 a, const Vec2& b) { return a -= b; }
  friend constexpr Vec2 operator*(Vec2 a, double s) { return {a.x * s, a.y * s}; }
  friend constexpr Vec2 operator*(double s, Vec2 a) { return {a.x * s, a.y * s}; }
  friend constexpr bool operator==(const Vec2&, const Vec2&) = default;
};
constexpr double dot(const Vec2& a, const Vec2& b) { return a.x * b.x + a.y * b.y; }
inline double norm(const Vec2& a) { return std::sqrt(dot(a, a)); }
inline double distance(const Vec2& a, const Vec2& b) { return norm(a - b); }
/// Unit vector along a; zero when |a| is zero or not finite.
inline Vec2 normalized(const Vec2& a) {
  const double n = norm(a);
  return (n > 0.0 && std::isfinite(n)) ? Vec2{a.x / n, a.y / n} : Vec2{};
}

/// Which numbers a level plays with: easy leaves more room for mistakes, hard has more guards
/// with sharper senses, more targets and artifacts whose differences are closer to what a hand
/// can tell apart.
enum class Difficulty : std::uint8_t { easy, hard };
const char* to_string(Difficulty difficulty);

/// One artifact piece as numbers: what Phantom's station needs to build the piece in its hands
/// (the kind, the difficulty, the size of the kind's surface feature, the material) and nothing
/// that says whether it is genuine. Only the server, which dealt the round, knows which form is
/// which piece; museum_artifacts makes the forms (piece_pairs) and builds meshes from them.
struct PieceForm {
  std::string kind{};  ///< as in Level::artifact_kinds
  Difficulty difficulty = Difficulty::easy;
  /// The kind's surface feature: the height of the amphora's and the scarab's ridge, the depth of
  /// the bowl's dent, the height of the goblet's seam [m] (0: none); the spacing of the tablet's
  /// grooves [m]; the number of the coin's reeds.
  double feature = 0.0;
  double stiffness = 0.0;         ///< the gradient law's coefficient [N/m^2]
  double friction_static = 0.0;   ///< Coulomb coefficient
  double friction_dynamic = 0.0;  ///< Coulomb coefficient
};

/// The two pieces of one artifact kind.
struct PiecePair {
  PieceForm genuine{};
  PieceForm forgery{};
};

/// An axis-aligned rectangle of floor [m]; a room or a doorway.
struct Room {
  std::string name{};
  Vec2 min{};
  Vec2 max{};
};

/// A glass display case; it holds one artifact or nothing.
struct DisplayCase {
  Vec2 pos{};  ///< its centre [m]
};

/// A guard's round: a closed loop of waypoints [m], each leg a straight walk across the floor.
struct PatrolRoute {
  std::vector<Vec2> waypoints{};
};

/// The speeds, senses and scores of a level (aggregate; defaults are the easy level's).
struct RuleNumbers {
  double tick_s = 1.0 / 60.0;         ///< one rule step [s]
  double round_s = 360.0;             ///< the round's time [s]
  double walk_speed = 1.4;            ///< Vive walking [m/s], silent
  double run_speed = 3.5;             ///< Vive running [m/s], heard within run_hear_radius
  double reach = 1.0;                 ///< Vive reaches a case or the table within this [m]
  double run_hear_radius = 4.0;       ///< guards hear running within this [m]
  double glass_hear_radius = 8.0;     ///< guards hear a case breaking within this [m]
  double view_range = 4.0;            ///< guards see Vive within this [m] ...
  double view_half_angle_deg = 25.0;  ///< ... and this angle either side of where they face
  double patrol_speed = 1.0;          ///< a guard on its round [m/s]
  double investigate_speed = 1.8;     ///< a guard walking to a noise [m/s]
  double linger_s = 4.0;              ///< how long a guard looks around where it heard a noise [s]
  double caught_penalty_s = 20.0;     ///< time lost when caught [s]
  double caught_grace_s = 3.0;        ///< after a catch, guards cannot catch again for this long [s]
  int genuine_points = 100;           ///< per genuine artifact Phantom keeps
  int forgery_penalty = 60;           ///< per forgery Phantom keeps
  double time_bonus_per_s = 1.0;      ///< points per second left when every target is settled early
};

/// The rule numbers by name, listed once: validate() checks each (`positive`: > 0, else >= 0) and
/// the welcome message tells clients those `told` (the browser draws its rings and cones from them).
struct RuleField {
  const char* name;
  double RuleNumbers::*value;
  bool positive;
  bool told;
};
inline constexpr RuleField kRuleFields[] = {
    {"tick_s", &RuleNumbers::tick_s, true, true},
    {"round_s", &RuleNumbers::round_s, true, true},
    {"walk_speed", &RuleNumbers::walk_speed, true, true},
    {"run_speed", &RuleNumbers::run_speed, true, true},
    {"reach", &RuleNumbers::reach, true, true},
    {"run_hear_radius", &RuleNumbers::run_hear_radius, true, true},
    {"glass_hear_radius", &RuleNumbers::glass_hear_radius, true, true},
    {"view_range", &RuleNumbers::view_range, true, true},
    {"view_half_angle_deg", &RuleNumbers::view_half_angle_deg, true, true},
    {"patrol_speed", &RuleNumbers::patrol_speed, true, false},
    {"investigate_speed", &RuleNumbers::investigate_speed, true, false},
    {"linger_s", &RuleNumbers::linger_s, false, false},
    {"caught_penalty_s", &RuleNumbers::caught_penalty_s, false, false},
    {"caught_grace_s", &RuleNumbers::caught_grace_s, false, false},
    {"time_bonus_per_s", &RuleNumbers::time_bonus_per_s, false, false},
};

/// The museum of one round: floor plan, cases, routes, artifacts and rule numbers.
struct Level {
  std::string name{};
  Difficulty difficulty = Difficulty::easy;
  std::vector<Room> rooms{};
  std::vector<DisplayCase> cases{};
  Vec2 table{};                       ///< Phantom's table, where Vive delivers [m]
  Vec2 entrance{};                    ///< where Vive starts, and is taken back to when caught [m]
  std::vector<PatrolRoute> routes{};  ///< one guard per route
  /// The artifact kinds on show (names of the artifact set, e.g. "amphora"); each round picks
  /// its targets among them.
  std::vector<std::string> artifact_kinds{};
  int target_count = 3;  ///< how many targets Falcon names
  RuleNumbers rules{};
  /// The two pieces of each kind, in the order of artifact_kinds (museum_artifacts::piece_pairs);
  /// the server needs them to tell Phantom's station what to build, the rules do not.
  std::vector<PiecePair> pieces{};
};

/// Capacities of the game state (game_state.hpp); validate() checks a level fits them.
inline constexpr int kMaxCases = 16;
inline constexpr int kMaxGuards = 8;
inline constexpr int kMaxTargets = 6;
inline constexpr int kMaxItems = 2 * kMaxTargets;  ///< a genuine and a forgery per target
inline constexpr int kMaxCarried = 2;              ///< Vive carries at most this many
inline constexpr int kMaxTrail = 8;                ///< turns a guard remembers to walk back along
inline constexpr int kMaxArtifactKinds = 32;

/// The shipped museum at a difficulty.
Level make_level(Difficulty difficulty);

/// Whether a point is on the floor (inside some room or doorway, borders included).
bool walkable(const Level& level, Vec2 p);
/// Whether the straight segment a-b stays on the floor: sampled every 2 cm, so walls (at least
/// 0.5 m thick in the shipped levels) are never skipped. Guards see and walk only along it.
bool clear_path(const Level& level, Vec2 a, Vec2 b);

/// Checks a level: capacities, every case, waypoint, the table and the entrance on the floor,
/// every patrol leg clear, enough cases for a genuine and a forgery per target, targets within
/// the kinds, numbers positive. The message names the part and what is wrong.
Status validate(const Level& level);

}  // namespace uh::museum
