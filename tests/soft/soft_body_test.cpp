// The packing rides along: a ball of spheres embedded in its lattice, pressed on top while its
// base is held. After every step, each sphere centre is inside the deformed tetrahedra and every
// node of the refitted tree bounds its children, both checked by brute force over all
// tetrahedra and nodes (not by the embedding's own bookkeeping); the loads spread from the
// spheres sum to the forces on them.

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <vector>

#include "uh/collette/sphere_tree.hpp"
#include "uh/collette/sphere_tree_builder.hpp"
#include "uh/soft/soft_body.hpp"

namespace uh::soft {
namespace {

constexpr double kBallRadius = 0.03;  // [m]
constexpr double kGrid = 0.005;       // sphere spacing [m]

bool in_ball(const Eigen::Vector3d& p) { return p.norm() < kBallRadius; }

// non-overlapping spheres on a grid, all inside the ball: a packing the test can see through
std::vector<Sphere> ball_packing() {
  std::vector<Sphere> leaves;
  const int n = static_cast<int>(kBallRadius / kGrid);
  for (int x = -n; x <= n; ++x)
    for (int y = -n; y <= n; ++y)
      for (int z = -n; z <= n; ++z) {
        const Eigen::Vector3d c = kGrid * Eigen::Vector3d(x, y, z);
        const double r = 0.45 * kGrid;
        if (c.norm() + r < kBallRadius)
          leaves.push_back({static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()),
                            static_cast<float>(r)});
      }
  return leaves;
}

Eigen::Vector3d centre(const Sphere& s) { return {double{s.x}, double{s.y}, double{s.z}}; }

// brute force: some tetrahedron at `positions` holds p (every barycentric weight >= -1e-9)
bool inside_some_tet(const TetMesh& mesh, const std::vector<Eigen::Vector3d>& positions, const Eigen::Vector3d& p) {
  for (const auto& t : mesh.tets) {
    Eigen::Matrix3d d;
    const Eigen::Vector3d& a = positions[static_cast<std::size_t>(t[0])];
    d << positions[static_cast<std::size_t>(t[1])] - a, positions[static_cast<std::size_t>(t[2])] - a,
        positions[static_cast<std::size_t>(t[3])] - a;
    const Eigen::Vector3d b = d.inverse() * (p - a);
    if (b.minCoeff() >= -1e-9 && 1.0 - b.sum() >= -1e-9) return true;
  }
  return false;
}

// brute force: each inner node's sphere contains each child's sphere (as the queries read them)
int nodes_not_bounding_children(const collette::SphereTree& tree) {
  int bad = 0;
  for (const auto& node : tree.nodes()) {
    if (node.is_leaf()) continue;
    for (int c = node.first; c < node.first + node.count; ++c) {
      const auto& child = tree.nodes()[static_cast<std::size_t>(c)];
      const double dx = double{child.x} - double{node.x}, dy = double{child.y} - double{node.y},
                   dz = double{child.z} - double{node.z};
      if (std::sqrt(dx * dx + dy * dy + dz * dz) + double{child.radius} > double{node.radius}) ++bad;
    }
  }
  return bad;
}

SoftBodyModel ball_body(const std::vector<Sphere>& leaves) {
  SoftBodyParams params;
  params.material = {.young_modulus_pa = 2.0e4, .poisson_ratio = 0.4, .density_kg_m3 = 1000.0,
                     .stiffness_damping_s = 0.01};
  params.target_tetrahedra = 1500;
  params.fixed = Box{.min = Eigen::Vector3d(-1.0, -1.0, -1.0), .max = Eigen::Vector3d(1.0, 1.0, -0.022)};
  auto body = build_soft_body(in_ball, leaves, params);
  EXPECT_TRUE(body) << body.error().message;
  return std::move(body).value();
}

TEST(SoftBody, AtRestTheEmbeddedSpheresAreThePacking) {
  const std::vector<Sphere> leaves = ball_packing();
  const SoftBodyModel body = ball_body(leaves);
  EXPECT_NEAR(static_cast<double>(body.mesh.tets.size()), 1500.0, 300.0);
  EXPECT_FALSE(body.fixed.empty());
  ASSERT_EQ(body.spheres.size(), leaves.size());
  std::vector<Sphere> moved(leaves.size());
  deform_spheres(body, body.mesh.nodes, moved);
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    EXPECT_NEAR(body.spheres[i].weights.sum(), 1.0, 1e-12);
    EXPECT_GE(body.spheres[i].weights.minCoeff(), 0.0);
    EXPECT_LT((centre(moved[i]) - centre(leaves[i])).norm(), 1e-7);
    EXPECT_NEAR(double{moved[i].radius}, double{leaves[i].radius}, 1e-6 * double{leaves[i].radius});
  }
}

// Sphere i's radius by an SVD of its element's deformation gradient, built here from the nodes
// (deform_spheres takes the eigenvalues of F^T F, once per element)
double reference_radius(const SoftBodyModel& body, const std::vector<Eigen::Vector3d>& positions, std::size_t i) {
  const EmbeddedSphere& e = body.spheres[i];
  const auto& t = body.mesh.tets[static_cast<std::size_t>(e.tet)];
  Eigen::Matrix3d now, rest;
  for (int c = 0; c < 3; ++c) {
    const auto a = static_cast<std::size_t>(t[0]), b = static_cast<std::size_t>(t[static_cast<std::size_t>(c + 1)]);
    now.col(c) = positions[b] - positions[a];
    rest.col(c) = body.mesh.nodes[b] - body.mesh.nodes[a];
  }
  const Eigen::Matrix3d f = now * rest.inverse();
  const double sigma = Eigen::JacobiSVD<Eigen::Matrix3d>(f).singularValues().minCoeff();
  return e.rest_radius * (f.determinant() > 0.0 ? std::max(sigma, kMinSphereStretch) : kMinSphereStretch);
}

TEST(SoftBody, PressedTheSpheresStayInsideAndTheRefittedTreeBoundsItsChildren) {
  const std::vector<Sphere> leaves = ball_packing();
  const SoftBodyModel body = ball_body(leaves);
  auto built = collette::build_sphere_tree(leaves);
  ASSERT_TRUE(built) << built.error().message;
  collette::SphereTree tree = std::move(built).value();
  ASSERT_TRUE(tree.refittable());
  auto fem = CorotationalFem::create(body.mesh, body.material, body.fixed);
  ASSERT_TRUE(fem) << fem.error().message;

  // 2 N down on the spheres of the top cap, spread to the nodes
  std::vector<Eigen::Vector3d> loads(body.mesh.nodes.size(), Eigen::Vector3d::Zero());
  Eigen::Vector3d applied = Eigen::Vector3d::Zero();
  std::vector<std::int32_t> cap;
  for (std::size_t i = 0; i < leaves.size(); ++i)
    if (leaves[i].z > 0.02f) cap.push_back(static_cast<std::int32_t>(i));
  ASSERT_FALSE(cap.empty());
  for (std::int32_t leaf : cap) {
    const Eigen::Vector3d f(0.0, 0.3 / static_cast<double>(cap.size()), -2.0 / static_cast<double>(cap.size()));
    spread_sphere_force(body, leaf, f, loads);
    applied += f;
  }
  Eigen::Vector3d spread = Eigen::Vector3d::Zero();
  for (const auto& l : loads) spread += l;
  EXPECT_LT((spread - applied).norm(), 1e-12);

  std::vector<Sphere> moved(leaves.size());
  double smallest_stretch = 1.0;
  for (int step = 0; step < 40; ++step) {
    ASSERT_TRUE(fem->step(0.005, loads));
    deform_spheres(body, fem->positions(), moved);
    tree.refit(moved);
    for (std::size_t i = 0; i < moved.size(); ++i) {
      ASSERT_TRUE(inside_some_tet(body.mesh, fem->positions(), centre(moved[i]))) << "step " << step << " sphere " << i;
      smallest_stretch = std::min(smallest_stretch, double{moved[i].radius} / double{leaves[i].radius});
      // the radius against its element's smallest singular value by an SVD of its own
      const double reference = reference_radius(body, fem->positions(), i);
      ASSERT_NEAR(double{moved[i].radius}, reference, 1e-6 * reference) << "step " << step << " sphere " << i;
    }
    ASSERT_EQ(nodes_not_bounding_children(tree), 0) << "step " << step;
  }
  ASSERT_TRUE(collette::validate(tree)) << collette::validate(tree).error().message;
  // it did deform: the top went down by millimetres and the spheres under it shrank
  double top_drop = 0.0;
  for (std::int32_t leaf : cap) top_drop = std::max(top_drop, double{leaves[static_cast<std::size_t>(leaf)].z} - double{moved[static_cast<std::size_t>(leaf)].z});
  EXPECT_GT(top_drop, 1e-3);
  EXPECT_LT(smallest_stretch, 0.97);
}

TEST(SoftBody, ABoxThatHoldsNothingIsRefusedAndTheDefaultSizeFollowsTheObject) {
  SoftBodyParams params;
  params.fixed = Box{.min = Eigen::Vector3d::Constant(5.0), .max = Eigen::Vector3d::Constant(6.0)};
  const auto body = build_soft_body(in_ball, ball_packing(), params);
  ASSERT_FALSE(body);
  EXPECT_NE(body.error().message.find("fixed box holds no node"), std::string::npos);
  EXPECT_EQ(default_tetrahedra(Eigen::Vector3d(0.1, 0.1, 0.05)), 3000);
  EXPECT_EQ(default_tetrahedra(Eigen::Vector3d(0.1, 0.1, 0.01)), 600);
  EXPECT_EQ(default_tetrahedra(Eigen::Vector3d(0.1, 0.01, 0.01)), 384);
}

}  // namespace
}  // namespace uh::soft
