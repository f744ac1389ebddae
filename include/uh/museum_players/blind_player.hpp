#pragma once
/// \file
/// The automated blind player (Phantom): tells a genuine artifact from a forgery by touch alone.
/// It explores the piece on a simulated device in simulated time with the exploration script of
/// `uh explore` (exploration::explore_scene: presses, strokes, contour following and taps) at
/// sites spread over the piece, planned from the packed shape's bounds only, and reads the device's
/// position and force trace: the material (exploration::estimate_material) and the surface its hand
/// traced along each stroke and contour. It compares them with a genuine reference of the same kind,
/// explored the same way, and calls the piece a forgery when a difference stands out of what two
/// explorations of the reference itself differ by. It never reads which piece is which, nor the
/// meshes. The judge (`uh museum judge`) runs it over every artifact pair of a level.
/// Setup code, not real-time.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "uh/controllers/scene.hpp"
#include "uh/core/result.hpp"
#include "uh/core/split_mix.hpp"
#include "uh/exploration/exploration.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum_artifacts/artifact.hpp"

namespace uh::museum_players {

/// One stretch of sliding (a stroke or a contour) as the hand traced it: where the surface was,
/// resampled at even steps along the way.
struct SurfaceTrack {
  std::string name;     ///< e.g. "side 25 % stroke up", "side 50 % around"
  bool around = false;  ///< once around the piece: the samples close on themselves (angle steps)
  double step = 0.0;    ///< between samples [m], or [rad] around
  double start = 0.0;   ///< where the first sample is along the stroke's axis [m] (around: angle 0)
  std::vector<double>
      height;  ///< the surface's height over the path (top: z, side: distance from the centre line) [m]
};

/// What the blind player read off one piece.
struct PieceSurvey {
  exploration::MaterialEstimate material;  ///< from the press, strokes and contour on the top
  /// Each press on the top: the force 0.8 mm past first contact over that depth [N/mm], by site
  /// ("top press 1" ..)
  std::vector<std::pair<std::string, double>> site_stiffness;
  std::vector<SurfaceTrack> tracks;
  double simulated_s = 0.0;  ///< device time the exploration took [s]
  std::uint64_t haptic_ticks = 0;
};

/// Settings of the survey (options aggregate).
struct SurveyOptions {
  double tool_radius_m = museum_artifacts::kStylusRadiusM;  ///< the stylus: a ball of this radius
  double haptic_hz = 1000.0;
  double ring_spacing_m = 0.008;     ///< side contours every this much of height [m]
  double max_piece_seconds = 240.0;  ///< budget of simulated time per piece [s]
  std::uint64_t seed = 1;            ///< moves the sites by up to 3 mm and the stroke turns
};

/// Explores `piece` (a scene object standing on its base, any turn about the vertical) with the
/// stylus. Sites: the top (press, four strokes, a circle, taps: the material); 12 presses with
/// the stylus on two rings round the top's middle (the stiffness); a raster of long
/// strokes over the top of a flat piece; on a piece with a round footprint, contours once around
/// it at heights every `ring_spacing_m` and strokes up and down its side.
Result<PieceSurvey> survey_piece(const controllers::SceneObject& piece, const SurveyOptions& options,
                                 const std::filesystem::path& cache_dir);

/// One feature compared: how far the piece is from the reference, and how far the reference is
/// from itself when explored twice (the noise); it counts as a difference above `threshold`.
struct FeatureDifference {
  std::string feature;  ///< "surface", "stiffness", "static friction", "dynamic friction", "texture ripple"
  std::string where;    ///< surface: the track; empty otherwise
  double difference = 0.0;  ///< surface: [mm]; material: relative (0.25 = 25 %)
  double noise = 0.0;       ///< the same between the two explorations of the reference
  double threshold = 0.0;
  std::string unit;  ///< "mm" or "%": how to read the three numbers
  /// stiffness: the chance that presses on two like pieces part at least this clearly (the rank
  /// test, core::rank_test_p_value); a difference counts only under kRankTestLevel. Empty elsewhere.
  std::optional<double> p_value;
  bool differs() const;
};

/// A stiffness difference counts only when the rank test puts the chance of one as clear between
/// like pieces under this (the judge compares about a dozen pieces per level: one in a hundred
/// levels would call a genuine piece a forgery on its presses' grain alone).
inline constexpr double kRankTestLevel = 0.001;

enum class Verdict : std::uint8_t { genuine, forgery };
const char* to_string(Verdict verdict);

struct Judgement {
  Verdict verdict = Verdict::genuine;
  std::vector<FeatureDifference> evidence;  ///< every feature compared, the largest surface difference first
};

/// Compares a piece with the genuine reference (explored twice, at two turns and seeds) and decides:
/// forgery when any feature differs by more than its threshold: the larger of a floor (a felt
/// difference: 0.3 mm of surface, 10 % of friction) and twice the noise. Stiffness: the piece's
/// presses against the reference's two sets together, a difference of their medians over 25 %
/// that the rank test finds under kRankTestLevel.
Judgement judge_piece(const PieceSurvey& piece, const PieceSurvey& reference,
                      const PieceSurvey& reference_again);

/// Whether a piece of this kind may lie on the table turned any way about its vertical axis
/// (pieces made on the lathe); slabs lie as they were made.
bool turned_on_the_table(museum_artifacts::ArtifactKind kind);

/// Where a piece lies before the blind player: turned about its vertical axis, shifted on the table.
struct Placement {
  double turn_rad = 0.0;
  double x = 0.0;  ///< [m]
  double y = 0.0;  ///< [m]
};
/// A place on the table dealt by `deal`: a lathe piece turned any way (turned_on_the_table), every
/// piece up to 2 mm off the middle. Draws the turn, then x, then y.
Placement place_on_table(museum_artifacts::ArtifactKind kind, core::SplitMix64& deal);

/// Explores the piece a form describes (museum_artifacts::check_form), lying at `at`.
Result<PieceSurvey> survey_form(const museum::PieceForm& form, const Placement& at,
                                const SurveyOptions& options, const std::filesystem::path& cache_dir);

/// A kind's genuine reference explored twice: how much it differs from itself.
struct Reference {
  PieceSurvey first;  ///< as made: no turn, no shift
  PieceSurvey again;  ///< placed as on the table
};
/// The reference study of the judge and the blind bot alike: the genuine piece explored as made,
/// then as on the table, the seeds and the placement drawn from `deal`. `before_each` (if set) is
/// called before each exploration (progress).
Result<Reference> study_reference(museum_artifacts::ArtifactKind kind, museum::Difficulty difficulty,
                                  const SurveyOptions& options, const std::filesystem::path& cache_dir,
                                  core::SplitMix64& deal, const std::function<void()>& before_each = {});

/// The judge: every artifact kind of a level, its genuine piece and its forgery put before the
/// blind player in an order and at turns dealt by the seed.
struct JudgeOptions {
  museum::Difficulty difficulty = museum::Difficulty::easy;
  std::uint64_t seed = 1;
  std::vector<museum_artifacts::ArtifactKind> kinds{museum_artifacts::kArtifactKinds.begin(),
                                                    museum_artifacts::kArtifactKinds.end()};
  SurveyOptions survey{};
  std::filesystem::path cache_dir;  ///< where the artifacts' meshes and packings are cached
  std::function<void(const std::string& what, double fraction)> progress;  ///< per piece explored
};

struct PieceResult {
  museum_artifacts::Piece truth = museum_artifacts::Piece::genuine;
  double turn_rad = 0.0;  ///< how the piece was turned about its axis on the table
  Judgement judgement;
  double simulated_s = 0.0;
  bool correct() const {
    return (truth == museum_artifacts::Piece::genuine) == (judgement.verdict == Verdict::genuine);
  }
};

struct PairResult {
  museum_artifacts::ArtifactKind kind{};
  std::string tell;                 ///< the shape tell (for the report; the player never reads it)
  std::string material_tell;        ///< the material tell, or empty
  std::vector<PieceResult> pieces;  ///< in the order they were judged
};

struct JudgeReport {
  museum::Difficulty difficulty{};
  std::uint64_t seed = 0;
  std::vector<PairResult> pairs;
  double accuracy = 0.0;  ///< correct verdicts / pieces judged
  double simulated_s = 0.0;
};

Result<JudgeReport> run_judge(const JudgeOptions& options);

}  // namespace uh::museum_players
