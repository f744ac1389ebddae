// The in-tree OBJ/STL reader (what the Windows build reads meshes with) against assimp, the
// independent reference, which load_mesh() uses in this build.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh_test_support.hpp"
#include "test_paths.hpp"
#include "uh/collette/mesh_import.hpp"

namespace uh::collette {
namespace {

using test::TempDir;
using test::Tri;

// both readers' meshes after the same welding and validation
struct Pair {
  TriangleMesh by_assimp;
  TriangleMesh built_in;
};

Pair read_both(const std::filesystem::path& path) {
  auto a = load_mesh(path);
  EXPECT_TRUE(a) << a.error().message;
  auto raw = read_obj_or_stl(path);
  EXPECT_TRUE(raw) << raw.error().message;
  if (!a || !raw) return {};
  auto b = validate_mesh(std::move(*raw));
  EXPECT_TRUE(b) << b.error().message;
  if (!b) return {};
  return {std::move(*a), std::move(*b)};
}

// The same surface: the same triangles on the same vertices, in the same order (both readers keep
// the file's order, and validation numbers the vertices by first use). Coordinates may differ in
// the last bit of their float: assimp's number parser does not always round to nearest, ours does.
void expect_same_mesh(const Pair& m, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(m.built_in.vertices.size(), m.by_assimp.vertices.size());
  EXPECT_EQ(m.built_in.triangles, m.by_assimp.triangles);
  const double diagonal = norm(mesh_bounds(m.by_assimp).max - mesh_bounds(m.by_assimp).min);
  const double tolerance = 1e-6 * diagonal;  // a few float ulps of the largest coordinate
  for (std::size_t i = 0; i < m.by_assimp.vertices.size(); ++i) {
    EXPECT_LE(norm(m.built_in.vertices[i] - m.by_assimp.vertices[i]), tolerance) << "vertex " << i;
  }
  EXPECT_EQ(m.built_in.report.boundary_edges, m.by_assimp.report.boundary_edges);
  EXPECT_NEAR(m.built_in.report.volume, m.by_assimp.report.volume, 1e-7 * m.by_assimp.report.volume);
}

void write_binary_stl(const std::filesystem::path& p, const TriangleMesh& m, const std::string& header_text) {
  std::ofstream out(p, std::ios::binary);
  char header[80] = {};
  std::memcpy(header, header_text.data(), std::min<std::size_t>(header_text.size(), sizeof header));
  out.write(header, sizeof header);
  const auto count = static_cast<std::uint32_t>(m.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const Tri& t : m.triangles) {
    float v[12] = {};
    for (int k = 0; k < 3; ++k) {
      const Vec3& x = m.vertices[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])];
      v[3 + 3 * k] = static_cast<float>(x.x);
      v[4 + 3 * k] = static_cast<float>(x.y);
      v[5 + 3 * k] = static_cast<float>(x.z);
    }
    out.write(reinterpret_cast<const char*>(v), sizeof v);
    out.write("\0\0", 2);
  }
}

TEST(ObjStlReader, MatchesAssimpOnTheCommittedMeshes) {
  for (const char* name : {"bunny_npm_3674.obj", "stylus.obj"}) {
    const Pair m = read_both(std::filesystem::path(UH_TEST_DATA_DIR) / "meshes" / name);
    expect_same_mesh(m, name);
  }
}

TEST(ObjStlReader, MatchesAssimpOnEveryLayout) {
  TempDir dir("obj_stl");
  const TriangleMesh sphere = test::icosphere(0.37, 2);
  const TriangleMesh ring = test::torus(1.0, 0.3, 12, 8);

  test::write_obj(dir / "plain.obj", sphere.vertices, sphere.triangles);
  {
    // corners with texture and normal numbers, negative (relative) numbers, comments, groups,
    // materials, CRLF line ends and a fourth (w) coordinate
    std::ofstream out(dir / "decorated.obj", std::ios::binary);
    out.precision(17);
    out << "# exported\r\nmtllib none.mtl\r\no sphere\r\ng part\r\nusemtl skin\r\ns 1\r\n";
    for (const Vec3& x : sphere.vertices)
      out << "v " << x.x << ' ' << x.y << ' ' << x.z << " 1.0\r\nvt 0.5 0.5\r\nvn 0 0 1\r\n";
    const auto n = static_cast<std::int32_t>(sphere.vertices.size());
    for (std::size_t f = 0; f < sphere.triangles.size(); ++f) {
      const Tri& t = sphere.triangles[f];
      if (f % 3 == 0) {
        out << "f " << t[0] + 1 << '/' << t[0] + 1 << '/' << t[0] + 1 << ' ' << t[1] + 1 << "//" << t[1] + 1
            << ' ' << t[2] + 1 << '/' << t[2] + 1 << "\r\n";
      } else if (f % 3 == 1) {
        out << "f " << t[0] - n << ' ' << t[1] - n << ' ' << t[2] - n << "\r\n";
      } else {
        out << "f  " << t[0] + 1 << "\t" << t[1] + 1 << ' ' << t[2] + 1 << " \r\n";
      }
    }
  }
  {
    // the torus as quads, as modelling tools export grids
    std::ofstream out(dir / "quads.obj");
    out.precision(17);
    for (const Vec3& x : ring.vertices) out << "v " << x.x << ' ' << x.y << ' ' << x.z << '\n';
    for (std::size_t f = 0; f + 1 < ring.triangles.size(); f += 2) {
      const Tri& a = ring.triangles[f];
      const Tri& b = ring.triangles[f + 1];  // (i,j) (i+1,j) (i+1,j+1) and (i,j) (i+1,j+1) (i,j+1)
      out << "f " << a[0] + 1 << ' ' << a[1] + 1 << ' ' << a[2] + 1 << ' ' << b[2] + 1 << '\n';
    }
  }
  test::write_stl(dir / "ascii.stl", sphere.vertices, sphere.triangles);
  write_binary_stl(dir / "binary.stl", sphere, "binary sphere");
  write_binary_stl(dir / "binary_solid.stl", ring, "solid but binary");

  for (const char* name :
       {"plain.obj", "decorated.obj", "quads.obj", "ascii.stl", "binary.stl", "binary_solid.stl"}) {
    expect_same_mesh(read_both(dir / name), name);
  }
}

TEST(ObjStlReader, ErrorsNameTheFileAndLine) {
  TempDir dir("obj_stl_errors");
  const struct {
    const char* name;
    const char* text;
    const char* expected;
  } cases[] = {
      {"coordinate.obj", "v 0 0 0\nv 1 x 0\n", "coordinate.obj:2: vertex coordinate 'x' is not a number"},
      {"short.obj", "v 0 0\n", "short.obj:1: a vertex needs 3 coordinates"},
      {"corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n",
       "corner.obj:4: face corner 'a' is not a vertex number"},
      {"zero.obj", "v 0 0 0\nf 0 1 2\n", "zero.obj:2: face corner '0' is not a vertex number"},
      {"relative.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\n",
       "relative.obj:3: face corner -3 refers to a vertex that does not exist (2 defined so far)"},
      {"edge.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n",
       "edge.obj:3: a face needs at least 3 corners, this one has 2"},
      {"four.stl",
       "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nvertex 1 1 0\n",
       "four.stl:7: a vertex outside a facet, or a facet with more than 3 vertices"},
      {"two.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\n",
       "two.stl:7: a facet with 2 vertices (3 expected)"},
      {"cut.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n",
       "cut.stl: the file ends inside a facet"},
      {"garbage.stl", "this is not a mesh at all", "garbage.stl: cannot read mesh: neither a binary STL"},
      {"cube.off", "OFF\n",
       "cube.off: cannot read mesh: the built-in reader reads OBJ (.obj) and STL (.stl) files only"},
  };
  for (const auto& c : cases) {
    { std::ofstream(dir / c.name, std::ios::binary) << c.text; }
    const auto r = read_obj_or_stl(dir / c.name);
    ASSERT_FALSE(r) << c.name;
    EXPECT_NE(r.error().message.find(c.expected), std::string::npos) << r.error().message;
  }
  const auto missing = read_obj_or_stl(dir / "missing.obj");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("missing.obj: cannot open the mesh file"), std::string::npos);
}

// The writer's text read back with the C library's own number parser (not fmt, which wrote it):
// every coordinate exactly, corners 1-based, and the built-in reader takes the text as it is.
TEST(ObjText, ReadsBackExactly) {
  TriangleMesh mesh;
  mesh.vertices = {{0.1, -2.0 / 3.0, 1e-7}, {1.0 / 7.0, 12345.678901234567, -0.0}, {3.0, 0.3, -1e300}};
  mesh.triangles = {{0, 1, 2}, {2, 1, 0}};
  const std::string text = obj_text(mesh, "two faces");
  std::istringstream in(text);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line, "# two faces");
  for (const Vec3& v : mesh.vertices) {
    ASSERT_TRUE(std::getline(in, line));
    ASSERT_EQ(line.substr(0, 2), "v ");
    char* end = line.data() + 2;
    const double x = std::strtod(end, &end), y = std::strtod(end, &end), z = std::strtod(end, &end);
    EXPECT_EQ(x, v.x);
    EXPECT_EQ(y, v.y);
    EXPECT_EQ(z, v.z);
    EXPECT_EQ(*end, '\0') << line;
  }
  for (const auto& t : mesh.triangles) {
    ASSERT_TRUE(std::getline(in, line));
    EXPECT_EQ(line, "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " +
                        std::to_string(t[2] + 1));
  }
  EXPECT_FALSE(std::getline(in, line)) << "nothing after the faces";
  EXPECT_EQ(obj_text(mesh, "").substr(0, 2), "v ") << "no comment line without a comment";

  const auto read = parse_obj_or_stl(text, "written.obj");
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->vertices.size(), 3u);
  EXPECT_EQ(read->triangles, mesh.triangles);
}

// The mesh JSON: exact by default and read back as written; scaled and rounded for pictures.
TEST(MeshJson, ReadsBackExactlyAndRoundsWhenAsked) {
  TriangleMesh mesh;
  mesh.vertices = {{0.1, -2.0 / 3.0, 1e-7}, {1.0 / 7.0, 12345.678901234567, -0.0}, {3.0, 0.3, -1e300}};
  mesh.triangles = {{0, 1, 2}, {2, 1, 0}};
  const auto read = parse_mesh_json(mesh_json(mesh).dump(), "written.json");
  ASSERT_TRUE(read) << read.error().message;
  EXPECT_EQ(read->source_name, "written.json");
  ASSERT_EQ(read->vertices.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(read->vertices[i].x, mesh.vertices[i].x);
    EXPECT_EQ(read->vertices[i].y, mesh.vertices[i].y);
    EXPECT_EQ(read->vertices[i].z, mesh.vertices[i].z);
  }
  EXPECT_EQ(read->triangles, mesh.triangles);

  mesh.vertices = {{0.123456, -0.00004, 2.0 / 3.0}};
  mesh.triangles = {};
  EXPECT_EQ(mesh_json(mesh, 10.0, 4)["vertices"].dump(), "[1.2346,-0.0004,6.6667]");
}

}  // namespace
}  // namespace uh::collette
