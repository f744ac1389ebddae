#include "uh/museum_artifacts/artifact.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "uh/collette/ist_builder.hpp"
#include "uh/collette/mesh_import.hpp"
#include "uh/forcecomp/virtual_coupling.hpp"

namespace uh::museum_artifacts {
namespace {

using museum::Difficulty;

TEST(MuseumArtifacts, EveryKindOfTheLevelsIsMadeHere) {
  for (const Difficulty d : {Difficulty::easy, Difficulty::hard}) {
    for (const std::string& name : museum::make_level(d).artifact_kinds) {
      const auto kind = artifact_kind(name);
      ASSERT_TRUE(kind.has_value()) << name;
      EXPECT_EQ(to_string(*kind), name);
    }
  }
  EXPECT_FALSE(artifact_kind("teapot").has_value());
  EXPECT_GE(kArtifactKinds.size(), 6u);
}

TEST(MuseumArtifacts, EveryPieceIsAClosedOutwardMeshAsGenerated) {
  for (const ArtifactKind kind : kArtifactKinds) {
    for (const Difficulty d : {Difficulty::easy, Difficulty::hard}) {
      for (const Piece piece : {Piece::genuine, Piece::forgery}) {
        collette::TriangleMesh mesh = artifact_mesh(kind, d, piece);
        const std::size_t vertices = mesh.vertices.size();
        EXPECT_GT(collette::mesh_volume(mesh), 0.0) << mesh.source_name << ": outward as generated";
        auto valid = collette::validate_mesh(std::move(mesh), {.repair = false});
        ASSERT_TRUE(valid.has_value()) << valid.error().message;
        const collette::MeshReport& r = valid->report;
        EXPECT_TRUE(r.closed_manifold()) << valid->source_name;
        EXPECT_EQ(r.inconsistent_edges, 0) << valid->source_name;
        EXPECT_FALSE(r.winding_flipped) << valid->source_name;
        EXPECT_EQ(r.components, 1) << valid->source_name;
        EXPECT_EQ(r.vertex_count, static_cast<std::int64_t>(vertices))
            << valid->source_name << ": nothing welded";
      }
    }
  }
}

TEST(MuseumArtifacts, AGenuinePieceAndItsForgeryLookAlikeButDifferByTheTell) {
  for (const ArtifactKind kind : kArtifactKinds) {
    for (const Difficulty d : {Difficulty::easy, Difficulty::hard}) {
      const collette::TriangleMesh g = artifact_mesh(kind, d, Piece::genuine);
      const collette::TriangleMesh f = artifact_mesh(kind, d, Piece::forgery);
      ASSERT_EQ(g.vertices.size(), f.vertices.size());
      ASSERT_EQ(g.triangles, f.triangles) << "one grid";
      double largest = 0.0;
      for (std::size_t i = 0; i < g.vertices.size(); ++i)
        largest = std::max(largest, norm(g.vertices[i] - f.vertices[i]));
      const Tell t = tell(kind, d);
      const std::string name = fmt::format("{} ({})", to_string(kind), museum::to_string(d));
      // the surfaces part by the tell's depth, and by no more
      EXPECT_GT(largest, 0.8 * t.depth) << name;
      EXPECT_LT(largest, 1.05 * t.depth) << name;
      // same size and almost the same volume: they look alike
      const collette::Aabb bg = collette::mesh_bounds(g);
      const collette::Aabb bf = collette::mesh_bounds(f);
      EXPECT_LE(norm(bg.min - bf.min), t.depth + 1e-12) << name;
      EXPECT_LE(norm(bg.max - bf.max), t.depth + 1e-12) << name;
      const double vg = collette::mesh_volume(g);
      EXPECT_LT(std::fabs(vg - collette::mesh_volume(f)) / vg, 0.03) << name;
    }
  }
}

TEST(MuseumArtifacts, HardTellsAreSubtlerThanEasyOnesYetAboveTheMillimetre) {
  for (const ArtifactKind kind : kArtifactKinds) {
    const Tell easy = tell(kind, Difficulty::easy);
    const Tell hard = tell(kind, Difficulty::hard);
    EXPECT_LT(hard.depth, easy.depth) << to_string(kind);
    EXPECT_GE(easy.depth, 0.0015) << to_string(kind);
    EXPECT_GE(hard.depth, 0.0009) << to_string(kind);
    EXPECT_FALSE(easy.description.empty());
    EXPECT_EQ(easy.feature, hard.feature);
  }
}

// how far a packing reaches along the line through `at` with direction `n` (unit) [m]: the
// highest point along the line of the leaf spheres it crosses
double packing_reach(const collette::SphereTree& tree, Vec3 at, Vec3 n) {
  double reach = -1.0;
  for (const Sphere& s : tree.leaves()) {
    const Vec3 c = Vec3{s.x, s.y, s.z} - at;
    const double along = dot(c, n);
    const double off2 = squared_norm(c - n * along);
    const double r = s.radius;
    if (off2 < r * r) reach = std::max(reach, along + std::sqrt(r * r - off2));
  }
  return reach;
}

// The finest tells (hard, under a millimetre) show in the packings of artifact_shape()'s default
// sphere count: along the line where the two surfaces part most, the packing of the piece with
// the bump reaches out further than the other's by at least half the tell
TEST(MuseumArtifacts, TheDefaultPackingResolvesTheFinestTells) {
  struct Finest {
    ArtifactKind kind;
    Piece bumped;  // the piece whose surface stands out at the tell
  };
  for (const Finest f :
       {Finest{ArtifactKind::scarab, Piece::genuine}, Finest{ArtifactKind::goblet, Piece::forgery}}) {
    const Piece plain = f.bumped == Piece::genuine ? Piece::forgery : Piece::genuine;
    const collette::TriangleMesh b = artifact_mesh(f.kind, Difficulty::hard, f.bumped);
    const collette::TriangleMesh p = artifact_mesh(f.kind, Difficulty::hard, plain);
    std::size_t at = 0;
    for (std::size_t i = 0; i < b.vertices.size(); ++i)
      if (norm(b.vertices[i] - p.vertices[i]) > norm(b.vertices[at] - p.vertices[at])) at = i;
    const Vec3 n = normalized(b.vertices[at] - p.vertices[at]);
    const auto packed_b = collette::build_ist_asset(b, 0, {.sphere_count = 10000});
    const auto packed_p = collette::build_ist_asset(p, 0, {.sphere_count = 10000});
    ASSERT_TRUE(packed_b.has_value() && packed_p.has_value());
    // from 5 mm inside the plain surface, along the outward direction of the tell
    const Vec3 start = p.vertices[at] - n * 0.005;
    const double reach_b = packing_reach(packed_b->asset.tree, start, n);
    const double reach_p = packing_reach(packed_p->asset.tree, start, n);
    const Tell t = tell(f.kind, Difficulty::hard);
    EXPECT_GT(reach_b - reach_p, 0.5 * t.depth)
        << to_string(f.kind) << ": reach " << reach_b << " vs " << reach_p << " from 5 mm inside";
  }
}

// Through the proxy the stylus feels a material as the spring 2 pi r k, capped by the coupling's
// passive stiffness: a stiffness tell is one a player feels only when both pieces lie below the
// cap, and then it is felt at its ratio. The table renders through the proxy whatever the default.
TEST(MuseumArtifacts, AStiffnessTellIsFeltThroughTheProxyAtItsRatio) {
  controllers::SceneObject piece;
  piece.name = "piece";
  const controllers::Scene table = table_scene(piece, nullptr, 1000.0);
  EXPECT_TRUE(table.force.proxy.enabled);
  const forcecomp::VirtualCouplingOptions& c = table.force.coupling;
  const double cap = std::min(c.stiffness, c.passivity_margin * forcecomp::max_passive_stiffness(
                                                                   c.device_damping, 1.0 / table.haptic_hz, c.damping));
  const auto felt = [cap](const forcecomp::Material& m) {
    return std::min(cap, 2.0 * std::numbers::pi * kStylusRadiusM * m.stiffness);
  };
  int told = 0;
  for (const ArtifactKind kind : kArtifactKinds) {
    for (const Difficulty d : {Difficulty::easy, Difficulty::hard}) {
      const MaterialTell t = material_tell(kind, d);
      if (t.property != "stiffness") continue;
      ++told;
      const forcecomp::Material genuine = artifact_material(kind, d, Piece::genuine);
      const forcecomp::Material forgery = artifact_material(kind, d, Piece::forgery);
      EXPECT_LT(felt(genuine), cap) << to_string(kind);
      EXPECT_NEAR(felt(forgery) / felt(genuine), t.ratio, 1e-9) << to_string(kind);
    }
  }
  EXPECT_EQ(told, 2) << "the bowl's resin, at both levels";
}

TEST(MuseumArtifacts, ShapesAreWrittenOnceAndPackedAndCachedLikeSceneObjects) {
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("uh-museum-artifacts-{}", ::getpid());
  std::filesystem::remove_all(dir);
  auto shape = artifact_shape(ArtifactKind::coin, Difficulty::hard, Piece::forgery, dir, 600);
  ASSERT_TRUE(shape.has_value()) << shape.error().message;
  EXPECT_EQ(shape->spheres, 600);
  ASSERT_TRUE(std::filesystem::exists(shape->mesh));
  const auto written = std::filesystem::last_write_time(shape->mesh);
  auto again = artifact_shape(ArtifactKind::coin, Difficulty::hard, Piece::forgery, dir, 600);
  ASSERT_TRUE(again.has_value());
  EXPECT_EQ(again->mesh, shape->mesh);
  EXPECT_EQ(std::filesystem::last_write_time(again->mesh), written) << "kept, not written again";
  // the genuine piece is another file
  auto genuine = artifact_shape(ArtifactKind::coin, Difficulty::hard, Piece::genuine, dir, 600);
  ASSERT_TRUE(genuine.has_value());
  EXPECT_NE(genuine->mesh, shape->mesh);

  const auto count_ist = [&] {
    int n = 0;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
      n += e.path().extension() == ".ist" ? 1 : 0;
    return n;
  };
  auto tree = controllers::load_shape_tree(*shape, dir);
  ASSERT_TRUE(tree.has_value()) << tree.error().message;
  EXPECT_GT(tree->coverage, 0.3);
  EXPECT_EQ(count_ist(), 1);
  auto cached = controllers::load_shape_tree(*shape, dir);
  ASSERT_TRUE(cached.has_value());
  EXPECT_EQ(count_ist(), 1) << "built once, then read from the cache";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace uh::museum_artifacts
