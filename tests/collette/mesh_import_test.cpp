#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <set>

#include "mesh_test_support.hpp"
#include "test_paths.hpp"
#include "uh/collette/mesh_import.hpp"

namespace uh::collette {
namespace {

using test::TempDir;
using test::unit_cube;

TEST(MeshImport, MissingFileIsAClearError) {
  const auto r = load_mesh("/nonexistent/dir/nothing_here.obj");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("nothing_here.obj"), std::string::npos);
  EXPECT_NE(r.error().message.find("not found"), std::string::npos);
  EXPECT_EQ(r.error().kind, uh::ErrorKind::kFile);  // the file's failure, not the mesh's
}

TEST(MeshImport, EmptyAndGarbageFilesAreClearErrors) {
  TempDir dir("garbage");
  { std::ofstream(dir / "empty.obj"); }
  {
    std::ofstream out(dir / "garbage.stl");
    out << "this is not a mesh at all \x01\x02\x03";
  }
  {
    std::ofstream out(dir / "no_faces.obj");
    out << "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  }
  for (const char* name : {"empty.obj", "garbage.stl", "no_faces.obj"}) {
    const auto r = load_mesh(dir / name);
    ASSERT_FALSE(r) << name;
    EXPECT_NE(r.error().message.find(name), std::string::npos) << r.error().message;
  }
}

TEST(MeshImport, ClosedCubeLoadsFromObjOffAndStl) {
  TempDir dir("cube");
  const TriangleMesh cube = unit_cube();
  test::write_obj(dir / "cube.obj", cube.vertices, cube.triangles);
  test::write_off(dir / "cube.off", cube.vertices, cube.triangles);
  test::write_stl(dir / "cube.stl", cube.vertices, cube.triangles);
  for (const char* name : {"cube.obj", "cube.off", "cube.stl"}) {
    const auto r = load_mesh(dir / name);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->source_name, name);
    EXPECT_EQ(r->report.vertex_count, 8) << name;
    EXPECT_EQ(r->report.triangle_count, 12) << name;
    EXPECT_EQ(r->report.boundary_edges, 0);
    EXPECT_EQ(r->report.components, 1);
    EXPECT_FALSE(r->report.winding_flipped);
    EXPECT_NEAR(mesh_volume(*r), 1.0, 1e-12);
    EXPECT_NEAR(r->report.volume, 1.0, 1e-12);
  }
}

TEST(MeshImport, StlIsWeldedByPosition) {
  TempDir dir("weld");
  const TriangleMesh cube = unit_cube();
  test::write_stl(dir / "cube.stl", cube.vertices, cube.triangles);
  const auto r = load_mesh(dir / "cube.stl");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->report.input_vertex_count, 36);
  EXPECT_EQ(r->report.welded_vertices, 28);
  EXPECT_EQ(r->vertices.size(), 8u);
}

TEST(MeshImport, WeldToleranceMergesNearDuplicates) {
  TriangleMesh cube = unit_cube();
  // a ninth vertex 1e-9 away from vertex 6, used by one triangle: only welding closes the mesh
  cube.vertices.push_back({1.0 + 1e-9, 1.0, 1.0});
  cube.triangles[2] = {4, 5, 8};
  const auto exact = validate_mesh(cube, {.weld_tolerance = 0.0});
  ASSERT_FALSE(exact);
  EXPECT_NE(exact.error().message.find("not"), std::string::npos);
  const auto welded = validate_mesh(cube, {.weld_tolerance = 1e-6});
  ASSERT_TRUE(welded) << welded.error().message;
  EXPECT_EQ(welded->vertices.size(), 8u);
  EXPECT_EQ(welded->report.welded_vertices, 1);
}

// Welding divides coordinates by the tolerance into grid cells: a vertex far from the rest (its
// cell past any integer) or a bounding box too large for a double (a NaN tolerance) must neither
// overflow nor stop the near-duplicates from merging. UBSan, in the sanitizer stage, watches the casts.
TEST(MeshImport, WeldingSurvivesCoordinatesFarBeyondTheTolerancesGrid) {
  TriangleMesh cube = unit_cube();
  cube.vertices.push_back({1.0 + 1e-11, 1.0, 1.0});
  cube.triangles[2] = {4, 5, 8};
  // used by no triangle, so dropped after welding; the diagonal it makes, 1.7e30, sets the
  // tolerance to 1.7e-10, and its cell index to 6e39
  cube.vertices.push_back({1e30, -1e30, 1e30});
  const auto welded = validate_mesh(cube, {.weld_tolerance = 1e-40, .degenerate_area_tolerance = 0.0});
  ASSERT_TRUE(welded) << welded.error().message;
  EXPECT_EQ(welded->vertices.size(), 8u);

  TriangleMesh huge = unit_cube();
  for (Vec3& v : huge.vertices) v = v * 1.5e308 - Vec3{0.75e308, 0.75e308, 0.75e308};
  huge.source_name = "huge.obj";
  const auto result = validate_mesh(huge, {.weld_tolerance = 1e-6});  // its diagonal overflows
  ASSERT_FALSE(result);
  EXPECT_NE(result.error().message.find("huge.obj"), std::string::npos) << result.error().message;
}

TEST(MeshImport, CubeMissingAFaceIsNotClosed) {
  TempDir dir("open");
  TriangleMesh cube = unit_cube();
  cube.triangles.resize(10);  // drop the +x face (two triangles)
  test::write_obj(dir / "open_cube.obj", cube.vertices, cube.triangles);
  const auto r = load_mesh(dir / "open_cube.obj");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find(
                "open_cube.obj: mesh is not closed: 4 boundary edges, 0 non-manifold edges (a closed "
                "2-manifold mesh is required)"),
            std::string::npos)
      << r.error().message;
  EXPECT_EQ(r.error().kind, uh::ErrorKind::kMesh);  // the file was read; the mesh is unusable
  // programs show the message as it is: it names no C++ type or option
  for (const char* cpp : {"MeshLoadOptions", "allow_open", "{.", "::", "repair ="})
    EXPECT_EQ(r.error().message.find(cpp), std::string::npos) << cpp << " in " << r.error().message;
}

TEST(MeshImport, AllowOpenAcceptsSmallHolesAndSaysSo) {
  TempDir dir("allow_open");
  TriangleMesh cube = unit_cube();
  cube.triangles.resize(10);
  test::write_obj(dir / "open_cube.obj", cube.vertices, cube.triangles);
  const auto r = load_mesh(dir / "open_cube.obj", {.allow_open = true});
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->report.assumed_open);
  EXPECT_EQ(r->report.boundary_edges, 4);
  const auto too_many = load_mesh(dir / "open_cube.obj", {.allow_open = true, .max_open_boundary_edges = 3});
  ASSERT_FALSE(too_many);
  EXPECT_NE(too_many.error().message.find("at most 3"), std::string::npos) << too_many.error().message;
}

TEST(MeshImport, FinIsNonManifold) {
  TempDir dir("fin");
  TriangleMesh cube = unit_cube();
  cube.vertices.push_back({0.5, -0.5, 1.5});
  cube.triangles.push_back({4, 5, 8});  // a third triangle on edge 4-5
  test::write_off(dir / "fin.off", cube.vertices, cube.triangles);
  const auto r = load_mesh(dir / "fin.off");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("fin.off: mesh is not 2-manifold: 2 boundary edges, 1 non-manifold edges"),
            std::string::npos)
      << r.error().message;
}

TEST(MeshImport, DegenerateFaceIsDroppedOrWithoutRepairRefused) {
  TempDir dir("degenerate");
  TriangleMesh cube = unit_cube();
  cube.vertices.push_back({0.5, 0.0, 0.0});  // on edge 0-1
  cube.triangles.push_back({0, 1, 8});       // zero area, distinct vertices
  test::write_obj(dir / "degenerate.obj", cube.vertices, cube.triangles);
  const auto r = load_mesh(dir / "degenerate.obj", {.repair = false});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find(
                "degenerate.obj: mesh has degenerate or duplicate faces: 0 boundary edges, 0 non-manifold "
                "edges, 1 degenerate faces, 0 duplicate faces"),
            std::string::npos)
      << r.error().message;
  const auto dropped = load_mesh(dir / "degenerate.obj");
  ASSERT_TRUE(dropped) << dropped.error().message;
  EXPECT_EQ(dropped->report.degenerate_faces, 1);
  EXPECT_TRUE(dropped->report.repaired);
  EXPECT_EQ(dropped->report.triangle_count, 12);
  EXPECT_EQ(dropped->vertices.size(), 8u);
}

// Sorted corner positions of each triangle: what a mesh is, independent of numbering.
std::multiset<std::array<double, 9>> triangle_set(const TriangleMesh& m) {
  std::multiset<std::array<double, 9>> out;
  for (const auto& t : m.triangles) {
    std::array<std::array<double, 3>, 3> corners{};
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec3& v = m.vertices[static_cast<std::size_t>(t[k])];
      corners[k] = {v.x, v.y, v.z};
    }
    std::sort(corners.begin(), corners.end());
    std::array<double, 9> flat{};
    for (std::size_t k = 0; k < 9; ++k) flat[k] = corners[k / 3][k % 3];
    out.insert(flat);
  }
  return out;
}

TEST(MeshImport, RepairDropsDegenerateAndDuplicateFacesOfAClosedMesh) {
  const TriangleMesh sphere = test::icosphere(1.0, 2);
  ASSERT_TRUE(validate_mesh(sphere));
  TriangleMesh broken = sphere;
  const auto n = static_cast<std::int32_t>(broken.vertices.size());
  // degenerate: repeated indices (3), a needle through an edge's midpoint (1), a face whose two
  // corners are distinct vertices at the same position, merged by welding (1)
  broken.triangles.push_back({0, 0, 1});
  broken.triangles.push_back({2, 3, 3});
  broken.triangles.push_back({4, 5, 4});
  const auto& e = sphere.triangles[10];
  broken.vertices.push_back(0.5 * (sphere.vertices[static_cast<std::size_t>(e[0])] +
                                   sphere.vertices[static_cast<std::size_t>(e[1])]));
  broken.triangles.push_back({e[0], e[1], n});
  broken.vertices.push_back(sphere.vertices[7]);
  broken.triangles.push_back({7, n + 1, 8});
  // duplicates: a copy, a reversed copy, and two more copies of one face (4)
  broken.triangles.push_back(sphere.triangles[5]);
  broken.triangles.push_back({sphere.triangles[9][0], sphere.triangles[9][2], sphere.triangles[9][1]});
  broken.triangles.push_back(sphere.triangles[20]);
  broken.triangles.push_back(sphere.triangles[20]);
  std::swap(broken.triangles[3], broken.triangles[broken.triangles.size() - 1]);  // the order does not matter
  const auto strict = validate_mesh(broken, {.repair = false});
  ASSERT_FALSE(strict);
  EXPECT_NE(strict.error().message.find("5 degenerate faces, 4 duplicate faces"), std::string::npos)
      << strict.error().message;
  const auto repaired = validate_mesh(broken);
  ASSERT_TRUE(repaired) << repaired.error().message;
  const MeshReport& r = repaired->report;
  EXPECT_EQ(r.degenerate_faces, 5);
  EXPECT_EQ(r.duplicate_faces, 4);
  EXPECT_TRUE(r.repaired);
  EXPECT_TRUE(r.closed_manifold());
  EXPECT_EQ(r.inconsistent_edges, 0);
  EXPECT_FALSE(r.winding_flipped);
  // exactly the original surface survives (compared as sets of corner positions)
  EXPECT_EQ(triangle_set(*repaired), triangle_set(sphere));
  EXPECT_EQ(repaired->vertices.size(), sphere.vertices.size());
  EXPECT_NEAR(r.volume, mesh_volume(sphere), 1e-12);
}

TEST(MeshImport, MeshStillOpenAfterRepairIsRefusedSayingWhatWasDropped) {
  TriangleMesh cube = unit_cube();
  cube.triangles.resize(10);                    // the +x face is missing
  cube.triangles.push_back({0, 0, 1});          // and a degenerate face
  cube.triangles.push_back(cube.triangles[2]);  // and a duplicate
  cube.source_name = "holey.obj";
  const auto r = validate_mesh(cube);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find(
                "holey.obj: mesh is not closed after dropping 1 degenerate and 1 duplicate faces: 4 "
                "boundary edges, 0 non-manifold edges"),
            std::string::npos)
      << r.error().message;
  const auto open = validate_mesh(cube, {.allow_open = true});
  ASSERT_TRUE(open) << open.error().message;
  EXPECT_TRUE(open->report.assumed_open);
  EXPECT_EQ(open->report.degenerate_faces, 1);
  EXPECT_EQ(open->report.duplicate_faces, 1);
}

TEST(MeshImport, InvertedCubeIsFlipped) {
  TempDir dir("inverted");
  TriangleMesh cube = unit_cube();
  for (auto& t : cube.triangles) std::swap(t[1], t[2]);
  ASSERT_LT(mesh_volume(cube), 0.0);
  test::write_obj(dir / "inverted.obj", cube.vertices, cube.triangles);
  const auto r = load_mesh(dir / "inverted.obj");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_TRUE(r->report.winding_flipped);
  EXPECT_NEAR(mesh_volume(*r), 1.0, 1e-12);
  // every triangle now has an outward normal: it points away from the cube's centre
  for (const auto& t : r->triangles) {
    const Vec3& a = r->vertices[static_cast<std::size_t>(t[0])];
    const Vec3& b = r->vertices[static_cast<std::size_t>(t[1])];
    const Vec3& c = r->vertices[static_cast<std::size_t>(t[2])];
    EXPECT_GT(dot(cross(b - a, c - a), (a + b + c) / 3.0 - Vec3{0.5, 0.5, 0.5}), 0.0);
  }
}

TEST(MeshImport, InconsistentOrientationIsReported) {
  TriangleMesh cube = unit_cube();
  std::swap(cube.triangles[0][1], cube.triangles[0][2]);
  cube.source_name = "patchy.obj";
  const auto r = validate_mesh(cube);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("patchy.obj: mesh orientation is inconsistent: 3 edges"),
            std::string::npos)
      << r.error().message;
}

TEST(MeshImport, IndexOutOfRangeIsAnError) {
  TriangleMesh cube = unit_cube();
  cube.triangles.push_back({0, 1, 99});
  EXPECT_FALSE(validate_mesh(cube));
}

TEST(MeshVolume, IcosphereApproachesTheBallVolume) {
  const double r = 2.0;
  const double ball = 4.0 / 3.0 * kPi * r * r * r;
  double previous_error = 1.0;
  for (int level = 1; level <= 4; ++level) {
    const auto m = validate_mesh(test::icosphere(r, level));
    ASSERT_TRUE(m) << m.error().message;
    const double v = mesh_volume(*m);
    EXPECT_LT(v, ball);  // inscribed polyhedron
    const double error = (ball - v) / ball;
    EXPECT_LT(error, previous_error / 3.0);  // about quartered per level
    previous_error = error;
  }
  EXPECT_LT(previous_error, 0.01);
}

TEST(MeshVolume, BoundsOfTheCube) {
  const Aabb b = mesh_bounds(unit_cube());
  EXPECT_EQ(b.min, (Vec3{0, 0, 0}));
  EXPECT_EQ(b.max, (Vec3{1, 1, 1}));
  EXPECT_GT(mesh_bounds(TriangleMesh{}).min.x, mesh_bounds(TriangleMesh{}).max.x);
}

TEST(MeshImport, BunnyAssetIsClosed) {
  const auto r = load_mesh(std::filesystem::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r->report.triangle_count, 3674);
  EXPECT_TRUE(r->report.closed_manifold());
  EXPECT_EQ(r->report.inconsistent_edges, 0);
  EXPECT_GT(r->report.volume, 0.0);
}

}  // namespace
}  // namespace uh::collette
