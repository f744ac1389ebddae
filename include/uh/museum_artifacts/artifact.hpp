#pragma once
/// \file
/// The museum's artifacts: six kinds, each as a genuine piece and a forgery that look the same but
/// differ by touch in shape (a seam, a missing ridge, a dent, a different groove spacing), at a
/// scale the sphere packing resolves. Meshes are generated (lathe profiles and relief on slabs),
/// nothing is loaded; each piece's .ist is built and cached like a scene object's.
///
/// Units: metres. Frame: the piece stands on its base at z = 0, centred on the z axis (slabs:
/// centred on the origin in x and y). Setup code, not real-time.

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "uh/collette/triangle_mesh.hpp"
#include "uh/controllers/scene.hpp"
#include "uh/core/result.hpp"
#include "uh/forcecomp/material.hpp"
#include "uh/museum/level.hpp"
#include "uh/museum/piece.hpp"

namespace uh::museum_artifacts {

/// The kinds, named as in museum::Level::artifact_kinds.
enum class ArtifactKind : std::uint8_t { amphora, bowl, coin, tablet, scarab, goblet };
inline constexpr std::array<ArtifactKind, 6> kArtifactKinds = {ArtifactKind::amphora, ArtifactKind::bowl,
                                                               ArtifactKind::coin,    ArtifactKind::tablet,
                                                               ArtifactKind::scarab,  ArtifactKind::goblet};
const char* to_string(ArtifactKind kind);
/// The kind named `name` ("amphora", ...), or none.
std::optional<ArtifactKind> artifact_kind(std::string_view name);

using museum::Piece;  // genuine or forgery (uh/museum/piece.hpp)
using museum::to_string;

/// How a kind's forgery differs from its genuine piece at a difficulty.
struct Tell {
  std::string feature{};      ///< "seam", "missing ridge", "dent" or "groove spacing"
  std::string description{};  ///< one sentence for the docs and the judge's report
  double depth = 0.0;         ///< the feature's height or depth [m]
  double width = 0.0;         ///< its width (grooves: the genuine spacing) [m]
};
/// Easy tells are 2-3 mm, hard ones about 1 mm: well above and near what a finger (and the
/// packing of artifact_shape()'s default sphere count) resolves.
Tell tell(ArtifactKind kind, museum::Difficulty difficulty);

/// The piece's closed surface (counter-clockwise seen from outside). A genuine piece and its
/// forgery share their vertex grid: vertex i of one is vertex i of the other, moved by the tell.
collette::TriangleMesh artifact_mesh(ArtifactKind kind, museum::Difficulty difficulty, Piece piece);

/// How a kind's forgery differs in material (besides its shape) at a difficulty: `property` is
/// "stiffness" or "friction" (both coefficients scale alike), and the forgery's value is `ratio`
/// times the genuine's; an empty property: the same material. Easy ratios are well above what a
/// hand tells apart (stiffness 15-45 %, friction about 20 %), hard ones near it.
struct MaterialTell {
  std::string property{};
  double ratio = 1.0;
  std::string description{};
};
MaterialTell material_tell(ArtifactKind kind, museum::Difficulty difficulty);

/// What the piece's surface feels like: the kind's material (fired clay, bronze, stone, silver...),
/// changed by material_tell() on a forgery. Through the proxy the stylus feels a material as the
/// spring 2 pi r k (r = kStylusRadiusM), capped by the coupling's passive stiffness (1.5 kN/m at
/// 1 kHz): every material stiffer than that feels the same, so a stiffness tell is made below it
/// (the bowl's glaze and resin).
forcecomp::Material artifact_material(ArtifactKind kind, museum::Difficulty difficulty, Piece piece);

/// The piece as the numbers a station builds it from (museum::PieceForm: no label); the mesh and
/// the material built from it are the piece's, to the bit.
museum::PieceForm piece_form(ArtifactKind kind, museum::Difficulty difficulty, Piece piece);
/// The two pieces of each of the level's kinds, in its order (for museum::Level::pieces); empty when
/// a kind is not one of the artifact set.
std::vector<museum::PiecePair> piece_pairs(const museum::Level& level);
/// The form's kind when the form is one a station builds: a known kind and its numbers within
/// bounds (a feature of at most 1 cm, 4..64 reeds, grooves 4..30 mm apart, a stiffness of
/// 1e3..1e7 N/m^2, friction within 0..2); else an error naming the number. A form comes from the
/// server: nothing it says makes the station build without bound.
Result<ArtifactKind> check_form(const museum::PieceForm& form);
/// The piece a form describes, once check_form() accepts it.
Result<collette::TriangleMesh> artifact_mesh(const museum::PieceForm& form);

/// Writes the piece's mesh as an OBJ file into `cache_dir`/museum-artifacts (named by kind,
/// difficulty and a hash of its content, never by piece; an existing file is kept) and returns the scene
/// shape that packs it with `spheres`: controllers::load_shape_tree() then builds and caches its
/// .ist as it does for any scene object.
Result<controllers::SceneShape> artifact_shape(ArtifactKind kind, museum::Difficulty difficulty, Piece piece,
                                               const std::filesystem::path& cache_dir,
                                               std::int64_t spheres = 10000);

Result<controllers::SceneShape> artifact_shape(const museum::PieceForm& form,
                                               const std::filesystem::path& cache_dir,
                                               std::int64_t spheres = 10000);

/// The piece as a scene object named `name` standing at `pose`: artifact_shape() and artifact_material().
Result<controllers::SceneObject> artifact_object(ArtifactKind kind, museum::Difficulty difficulty,
                                                 Piece piece, const std::filesystem::path& cache_dir,
                                                 const std::string& name, const Pose& pose = {},
                                                 std::int64_t spheres = 10000);
/// The piece a form describes (Phantom's station: the form the server sent) as a scene object.
Result<controllers::SceneObject> artifact_object(const museum::PieceForm& form,
                                                 const std::filesystem::path& cache_dir,
                                                 const std::string& name, const Pose& pose = {},
                                                 std::int64_t spheres = 10000);

/// The stylus Phantom holds, at the station and in the blind player's hand: a ball of this radius [m].
inline constexpr double kStylusRadiusM = 0.004;

/// The scene of a piece on Phantom's table, felt with `tool` (a ball: the stylus, or a finger's
/// pad) at `haptic_hz` (the collision thread at the same rate): the piece watched, the device and
/// its settings left to the caller. Rendered through the 6-DOF proxy whatever the scene default
/// is (ToolProxyOptions::enabled): the stylus stays on the side of the surface it came from, and
/// what the hand feels (a shape, friction, a stiffness within what the coupling renders
/// passively) is what a player is asked to judge. The station and the blind player both play on it.
controllers::Scene table_scene(const controllers::SceneObject& piece,
                               std::shared_ptr<const collette::SphereTree> tool, double haptic_hz);

}  // namespace uh::museum_artifacts
