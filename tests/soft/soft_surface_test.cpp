// The drawn surface rides along: a block's mesh, refined, embedded in its lattice. At rest the
// deformed vertices are the mesh's; pressed, each one is where a reference computed here puts it
// (its own barycentric solve in the tetrahedron that holds it, found by brute force, or for a
// vertex outside the lattice the tetrahedron with the nearest centroid), and the vertices in the
// fixed box stay put.

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <vector>

#include "uh/soft/soft_body.hpp"
#include "uh/soft/surface_mesh.hpp"

namespace uh::soft {
namespace {

// a 6 x 6 x 2 cm block, its top at z = 0
const Eigen::Vector3d kLo(-0.03, -0.03, -0.02), kHi(0.03, 0.03, 0.0);
constexpr double kGrid = 0.004;  // sphere spacing [m]

bool in_block(const Eigen::Vector3d& p) { return (p.array() > kLo.array()).all() && (p.array() < kHi.array()).all(); }

std::vector<Sphere> block_packing() {
  std::vector<Sphere> leaves;
  const double r = 0.45 * kGrid;
  for (double x = kLo.x() + kGrid / 2; x < kHi.x(); x += kGrid)
    for (double y = kLo.y() + kGrid / 2; y < kHi.y(); y += kGrid)
      for (double z = kLo.z() + kGrid / 2; z < kHi.z(); z += kGrid)
        leaves.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), static_cast<float>(r)});
  return leaves;
}

SurfaceMesh block_surface() {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i)
    v.push_back({(i & 1) ? kHi.x() : kLo.x(), (i & 2) ? kHi.y() : kLo.y(), (i & 4) ? kHi.z() : kLo.z()});
  const std::vector<std::array<std::int32_t, 3>> t = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return refine_surface(v, t);
}

const Box kFixed{.min = Eigen::Vector3d(-1.0, -1.0, -1.0), .max = Eigen::Vector3d(1.0, 1.0, -0.0185)};

SoftBodyModel block_body() {
  SoftBodyParams params;
  params.material = {.young_modulus_pa = 2.0e4, .poisson_ratio = 0.4, .density_kg_m3 = 1000.0,
                     .stiffness_damping_s = 0.01};
  params.target_tetrahedra = 1200;
  params.fixed = kFixed;
  params.surface = block_surface();
  auto body = build_soft_body(in_block, block_packing(), params);
  EXPECT_TRUE(body) << body.error().message;
  return std::move(body).value();
}

Eigen::Vector3d vertex(const std::vector<float>& xyz, std::size_t i) {
  return {double{xyz[3 * i]}, double{xyz[3 * i + 1]}, double{xyz[3 * i + 2]}};
}

// p's barycentric weights in tetrahedron t at `positions`, by a 4 x 4 solve
Eigen::Vector4d weights(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& positions, std::size_t t,
                        const Eigen::Vector3d& p) {
  Eigen::Matrix4d a;
  for (int k = 0; k < 4; ++k)
    a.col(k) << positions[static_cast<std::size_t>(mesh.tets[t][static_cast<std::size_t>(k)])], 1.0;
  return a.fullPivLu().solve(Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0));
}

Eigen::Vector3d centroid(const TetMesh& mesh, std::size_t t) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::int32_t n : mesh.tets[t]) c += 0.25 * mesh.nodes[static_cast<std::size_t>(n)];
  return c;
}

// the reference: the tetrahedron holding the rest vertex (brute force), else the one with the
// nearest centroid; the vertex at its rest weights in that tetrahedron's deformed nodes
Eigen::Vector3d reference(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& deformed, const Eigen::Vector3d& rest) {
  std::size_t chosen = mesh.tets.size();
  for (std::size_t t = 0; t < mesh.tets.size() && chosen == mesh.tets.size(); ++t)
    if (weights(mesh, mesh.nodes, t, rest).minCoeff() >= -1e-9) chosen = t;
  if (chosen == mesh.tets.size()) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
      if (const double d = (centroid(mesh, t) - rest).norm(); d < nearest) {
        nearest = d;
        chosen = t;
      }
  }
  const Eigen::Vector4d w = weights(mesh, mesh.nodes, chosen, rest);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int k = 0; k < 4; ++k) p += w[k] * deformed[static_cast<std::size_t>(mesh.tets[chosen][static_cast<std::size_t>(k)])];
  return p;
}

TEST(SoftSurface, TheRefinedMeshStaysClosedAndBounded) {
  const SurfaceMesh s = block_surface();
  // 12 triangles split four ways until edges are at most 6 cm / 16 (the diagonal 8.5 cm: 5 times)
  EXPECT_EQ(s.triangles.size(), 12u * 1024u);
  EXPECT_EQ(s.vertices.size(), s.triangles.size() / 2 + 2);  // Euler: a closed, welded surface
  EXPECT_LE(s.triangles.size(), kMaxSurfaceTriangles);
}

TEST(SoftSurface, AtRestTheDeformedVerticesAreTheMesh) {
  const SoftBodyModel body = block_body();
  ASSERT_EQ(body.surface_embedding.size(), body.surface.vertices.size());
  std::vector<float> xyz(3 * body.surface.vertices.size());
  deform_surface(body, body.mesh.nodes, xyz);
  int outside = 0;
  for (std::size_t i = 0; i < body.surface.vertices.size(); ++i) {
    EXPECT_LT((vertex(xyz, i) - body.surface.vertices[i]).norm(), 1e-7) << "vertex " << i;
    const EmbeddedVertex& e = body.surface_embedding[i];
    if (e.tet != EmbeddedVertex::kHeldVertex) {
      EXPECT_NEAR(e.weights.sum(), 1.0, 1e-12);
      outside += e.weights.minCoeff() < -1e-9 ? 1 : 0;
    }
  }
  EXPECT_GT(outside, 0);  // the lattice's staircase: some vertices are extrapolated
}

TEST(SoftSurface, PressedEachVertexFollowsItsTetrahedronAndTheHeldOnesStay) {
  const SoftBodyModel body = block_body();
  auto fem = CorotationalFem::create(body.mesh, body.material, body.fixed);
  ASSERT_TRUE(fem) << fem.error().message;
  // 2 N down on the nodes of the top near the centre
  std::vector<Eigen::Vector3d> loads(body.mesh.nodes.size(), Eigen::Vector3d::Zero());
  std::vector<std::size_t> pressed;
  for (std::size_t n = 0; n < body.mesh.nodes.size(); ++n)
    if (body.mesh.nodes[n].z() > -0.003 && body.mesh.nodes[n].head<2>().norm() < 0.01) pressed.push_back(n);
  ASSERT_FALSE(pressed.empty());
  for (std::size_t n : pressed) loads[n] = Eigen::Vector3d(0.0, 0.0, -2.0 / static_cast<double>(pressed.size()));
  for (int step = 0; step < 20; ++step) ASSERT_TRUE(fem->step(0.01, loads));

  std::vector<float> xyz(3 * body.surface.vertices.size());
  deform_surface(body, fem->positions(), xyz);
  double top_drop = 0.0;
  int held = 0;
  for (std::size_t i = 0; i < body.surface.vertices.size(); ++i) {
    const Eigen::Vector3d& rest = body.surface.vertices[i];
    const Eigen::Vector3d moved = vertex(xyz, i);
    if ((rest.array() >= kFixed.min.array()).all() && (rest.array() <= kFixed.max.array()).all()) {
      EXPECT_LT((moved - rest).norm(), 1e-7) << "held vertex " << i;
      ++held;
      continue;
    }
    if (i % 7 == 0) {  // the brute-force reference on a seventh of them (it is O(vertices x tets))
      EXPECT_LT((moved - reference(body.mesh, fem->positions(), rest)).norm(), 1e-7) << "vertex " << i;
    }
    if (rest.z() == 0.0 && rest.head<2>().norm() < 0.005) top_drop = std::max(top_drop, rest.z() - moved.z());
  }
  EXPECT_GT(held, 100);  // the bottom face
  EXPECT_GT(top_drop, 5e-4);  // it did deform under the load
}

}  // namespace
}  // namespace uh::soft
