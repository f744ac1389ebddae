// The `uh` program as its users call it: `uh ist build/info/preview` and `uh query` with the
// documented arguments and outputs (docs/collette-queries.md), checked against the library and a
// brute-force sum over the leaf spheres, and its errors on bad input.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "haply_standin.hpp"

#include "lens_reference.hpp"
#include "test_paths.hpp"
#include "uh/collette/ist_file.hpp"

namespace uh {
namespace {

namespace fs = std::filesystem;

struct CommandRun {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A scratch directory per test program run, removed at the end.
class CliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / fmt::format("uh_cli_test_{}", ::getpid());
    fs::create_directories(dir_);
    // one small tree shared by the query tests
    const CommandRun r = uh(fmt::format("ist build '{}' -o '{}' --spheres 600 --json", bunny().string(),
                                        (dir_ / "bunny.ist").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path bunny() { return fs::path(UH_TEST_DATA_DIR) / "meshes" / "bunny_npm_3674.obj"; }

  // `shell_prefix` runs before the program in the same shell (e.g. a ulimit)
  static CommandRun uh(const std::string& arguments, const std::string& shell_prefix = "") {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command = fmt::format("{}'{}' {} > '{}' 2> '{}'", shell_prefix, UH_CLI_PATH, arguments,
                                            out.string(), err.string());
    const int status = std::system(command.c_str());
    CommandRun r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_text(out);
    r.err = read_text(err);
    return r;
  }

  static nlohmann::json json_of(const CommandRun& r) {
    try {
      return nlohmann::json::parse(r.out);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not JSON: " << e.what() << "\n" << r.out;
      return {};
    }
  }

  static fs::path dir_;
};

fs::path CliTest::dir_;

// Poses of B in A: a path sliding B's copy of the bunny through A's, then one far away.
fs::path write_poses(const fs::path& path, int steps, double from, double to) {
  std::ofstream out(path);
  out << "id,tx,ty,tz,qw,qx,qy,qz,comment\n";
  for (int k = 0; k < steps; ++k) {
    const double x = from + (to - from) * k / std::max(1, steps - 1);
    const double half = 0.002 * k;  // a slow turn about y
    out << "p" << k << "," << x << ",0.1,0," << std::cos(half) << ",0," << std::sin(half)
        << ",0,extra column\n";
  }
  out << "far,50,0,0,1,0,0,0,\n";
  return path;
}

// Brute force over all leaf pairs: the intersection volume of the packings at one pose.
Vec3 centre(const Sphere& s) {
  return {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
}

double brute_volume(const collette::SphereTree& a, const collette::SphereTree& b, const Pose& b_in_a) {
  double v = 0.0;
  for (const Sphere& sb : b.leaves()) {
    const Vec3 cb = transform_point(b_in_a, centre(sb));
    for (const Sphere& sa : a.leaves())
      v += uh::test::lens_reference(norm(cb - centre(sa)), static_cast<double>(sa.radius),
                                    static_cast<double>(sb.radius))
               .volume;
  }
  return v;
}

// d(brute_volume)/d(translation of B) by central differences
Vec3 brute_volume_gradient(const collette::SphereTree& a, const collette::SphereTree& b, const Pose& b_in_a,
                           double h) {
  Vec3 g;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 e{};
    (axis == 0 ? e.x : axis == 1 ? e.y : e.z) = h;
    const double d = (brute_volume(a, b, {b_in_a.rotation, b_in_a.position + e}) -
                      brute_volume(a, b, {b_in_a.rotation, b_in_a.position - e})) /
                     (2 * h);
    (axis == 0 ? g.x : axis == 1 ? g.y : g.z) = d;
  }
  return g;
}

TEST_F(CliTest, IstBuildPrintsTheDocumentedFieldsAndInfoAgrees) {
  const fs::path ist = dir_ / "build.ist", png = dir_ / "build.png";
  const CommandRun r = uh(fmt::format("ist build '{}' -o '{}' --spheres 400 --preview '{}' --json",
                                      bunny().string(), ist.string(), png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = json_of(r);
  for (const char* key :
       {"spheres", "mesh_volume", "sphere_volume", "coverage", "max_gap", "build_seconds", "nodes", "depth"})
    EXPECT_TRUE(j.contains(key)) << "missing " << key << " in " << r.out;
  EXPECT_EQ(j.value("spheres", 0), 400);
  EXPECT_NEAR(j.value("coverage", 0.0), j.value("sphere_volume", 0.0) / j.value("mesh_volume", 1.0), 1e-9);
  EXPECT_GT(j.value("coverage", 0.0), 0.5);
  EXPECT_LT(j.value("coverage", 1.0), 1.0);
  EXPECT_TRUE(fs::exists(ist));
  EXPECT_EQ(read_text(png).substr(0, 4), "\x89PNG");

  const auto asset = collette::load_ist(ist);
  ASSERT_TRUE(asset.has_value()) << asset.error().message;
  EXPECT_EQ(asset->tree.leaf_count(), 400);
  EXPECT_EQ(asset->tree.node_count(), j.value("nodes", -1));
  EXPECT_EQ(asset->tree.depth(), j.value("depth", -1));

  const CommandRun info = uh(fmt::format("ist info '{}' --json", ist.string()));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const auto ji = json_of(info);
  EXPECT_EQ(ji.value("spheres", 0), 400) << info.out;
  EXPECT_NEAR(ji.value("coverage", 0.0), j.value("coverage", 0.0), 1e-6);
  // the build keeps the mesh it packed: format 2, with the surface section
  ASSERT_TRUE(asset->surface.has_value());
  EXPECT_EQ(ji.value("format_version", 0), 2) << info.out;
  EXPECT_EQ(ji.value("surface_triangles", std::size_t{0}), asset->surface->triangles.size()) << info.out;
  EXPECT_GT(ji.value("surface_triangles", 0), 0) << info.out;

  const fs::path section = dir_ / "section.png";
  const CommandRun preview =
      uh(fmt::format("ist preview '{}' -o '{}' --section", ist.string(), section.string()));
  ASSERT_EQ(preview.exit_code, 0) << preview.err;
  EXPECT_EQ(read_text(section).substr(0, 4), "\x89PNG");
}

TEST_F(CliTest, QueryMatchesBruteForceAndWritesTheDocumentedCsv) {
  const fs::path ist = dir_ / "bunny.ist";
  const fs::path poses = write_poses(dir_ / "poses.csv", 5, -4.0, 2.0);
  const fs::path csv = dir_ / "results.csv";
  const CommandRun r = uh(
      fmt::format("query '{0}' '{0}' --poses '{1}' --out '{2}'", ist.string(), poses.string(), csv.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "id,volume,nx,ny,nz,pairs,distance,time_us,volume_estimate");
  const auto asset = collette::load_ist(ist);
  ASSERT_TRUE(asset.has_value());
  std::vector<std::string> ids;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) f.push_back(cell);
    ASSERT_EQ(f.size(), 9u) << line;
    ids.push_back(f[0]);
    const double volume = std::stod(f[1]);
    const Vec3 n{std::stod(f[2]), std::stod(f[3]), std::stod(f[4])};
    const double distance = std::stod(f[6]);
    if (f[0] == "far") {
      EXPECT_EQ(volume, 0.0);
      EXPECT_EQ(norm(n), 0.0);
      EXPECT_EQ(std::stod(f[8]), 0.0);
      EXPECT_GT(distance, 35.0);  // 50 apart, the bunny is about 10 units wide
      continue;
    }
    const int k = std::stoi(f[0].substr(1));
    const double x = -4.0 + 6.0 * k / 4.0, half = 0.002 * k;
    const Pose pose{{std::cos(half), 0.0, std::sin(half), 0.0}, {x, 0.1, 0.0}};
    const double expected = brute_volume(asset->tree, asset->tree, pose);
    ASSERT_GT(expected, 0.0) << line;
    EXPECT_NEAR(volume, expected, 1e-4 * expected) << line;
    EXPECT_NEAR(norm(n), 1.0, 1e-6) << line;
    EXPECT_EQ(distance, 0.0) << line;
    EXPECT_GT(std::stoll(f[5]), 0) << line;
    // nx, ny, nz: the direction of the gradient law's force on B, minus the volume's gradient
    const Vec3 expected_direction = normalized(-brute_volume_gradient(asset->tree, asset->tree, pose, 1e-3));
    EXPECT_GT(dot(n, expected_direction), std::cos(0.5 * kPi / 180.0)) << line;
    // B's copy is shifted along x: the force pushes it further that way
    if (std::abs(x) > 1.0) {
      EXPECT_GT(n.x * x, 0.0) << line;
    }
    // the coverage-calibrated estimate of the meshes' overlap
    EXPECT_NEAR(std::stod(f[8]), volume / (asset->meta.coverage * asset->meta.coverage), 1e-6 * volume)
        << line;
  }
  EXPECT_EQ(ids, (std::vector<std::string>{"p0", "p1", "p2", "p3", "p4", "far"}));
}

TEST_F(CliTest, QueryJsonSummaryAndCoherentPathGiveTheSameResults) {
  const fs::path ist = dir_ / "bunny.ist";
  const fs::path poses = write_poses(dir_ / "path.csv", 60, -3.0, -2.5);
  const CommandRun plain =
      uh(fmt::format("query '{0}' '{0}' --poses '{1}' --json", ist.string(), poses.string()));
  const CommandRun coherent = uh(fmt::format("query '{0}' '{0}' --poses '{1}' --json --coherence-skin 0.2",
                                             ist.string(), poses.string()));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  ASSERT_EQ(coherent.exit_code, 0) << coherent.err;
  const auto jp = json_of(plain), jc = json_of(coherent);
  for (const char* key : {"median", "p99", "max"}) EXPECT_GT(jp["time_us"].value(key, 0.0), 0.0) << key;
  ASSERT_EQ(jp["results"].size(), 61u);
  ASSERT_EQ(jc["results"].size(), 61u);
  for (std::size_t i = 0; i < 61; ++i) {
    const auto& a = jp["results"][i];
    const auto& b = jc["results"][i];
    EXPECT_EQ(a["pairs"], b["pairs"]) << i;
    for (const char* key : {"nx", "ny", "nz", "volume_estimate"}) EXPECT_TRUE(a.contains(key)) << key;
    EXPECT_NEAR(a["volume"].get<double>(), b["volume"].get<double>(),
                1e-12 + 1e-9 * a["volume"].get<double>())
        << i;
  }
  EXPECT_GT(jc["coherence"].value("reused_poses", 0), 40)
      << "small steps along the path should reuse the kept pairs";
}

TEST_F(CliTest, QuaternionsAreNormalisedWhateverTheirScale) {
  const fs::path ist = dir_ / "bunny.ist";
  const fs::path poses = dir_ / "scaled.csv";
  {
    std::ofstream out(poses);
    const double c = std::cos(0.1), s = std::sin(0.1);
    // comment lines and blank lines are skipped
    out << "# scaled copies of one rotation\nid,tx,ty,tz,qw,qx,qy,qz\n\n";
    for (const double scale : {1.0, 1e-200, 1e200, 3.0})
      out << "s" << scale << ",-2,0.1,0," << c * scale << ",0," << s * scale << ",0\n# next\n";
  }
  const CommandRun r =
      uh(fmt::format("query '{0}' '{0}' --poses '{1}' --json", ist.string(), poses.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = json_of(r);
  ASSERT_EQ(j["results"].size(), 4u);
  const double v0 = j["results"][0]["volume"].get<double>();
  ASSERT_GT(v0, 0.0);
  for (const auto& row : j["results"]) EXPECT_NEAR(row["volume"].get<double>(), v0, 1e-9 * v0) << row.dump();
}

// A unit cube as OBJ with extra faces appended (1-based indices as OBJ has them).
fs::path write_cube(const fs::path& path, bool drop_top, const std::string& extra_faces) {
  std::ofstream out(path);
  out << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 0.5 0 0\n"
         "f 1 3 2\nf 1 4 3\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 1 5 8\nf 1 8 4\n";
  if (!drop_top) out << "f 5 6 7\nf 5 7 8\n";
  out << extra_faces;
  return path;
}

TEST_F(CliTest, IstBuildRepairsDegenerateAndDuplicateFacesAndSaysWhat) {
  // two degenerate faces (a repeated vertex; a needle through vertex 9 on edge 1-2) and four
  // duplicates (a copy and a reversed copy of one face, two copies of another)
  const std::string extra = "f 1 1 2\nf 1 2 9\nf 1 3 2\nf 1 2 3\nf 3 8 7\nf 3 8 7\n";
  const fs::path mesh = write_cube(dir_ / "repairable.obj", false, extra);
  const fs::path out = dir_ / "repairable.ist";
  const CommandRun r =
      uh(fmt::format("ist build '{}' -o '{}' --spheres 30 --json", mesh.string(), out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = json_of(r);
  EXPECT_EQ(j["repaired"]["degenerate_faces"], 2);
  EXPECT_EQ(j["repaired"]["duplicate_faces"], 4);
  EXPECT_EQ(j["triangles"], 12);
  EXPECT_EQ(j["open_boundary_edges"], 0);
  EXPECT_NEAR(j["mesh_volume"].get<double>(), 1.0, 1e-12);
  EXPECT_TRUE(collette::load_ist(out));
  const CommandRun human =
      uh(fmt::format("ist build '{}' -o '{}' --spheres 30", mesh.string(), out.string()));
  ASSERT_EQ(human.exit_code, 0) << human.err;
  EXPECT_NE(human.out.find("repaired: dropped 2 degenerate faces; dropped 4 duplicate faces\n"),
            std::string::npos)
      << human.out;
}

// A unit cube as the mesh JSON, its last `drop` triangles left out (an open box).
std::string cube_json(int drop = 0) {
  nlohmann::json vertices = nlohmann::json::array(), triangles = nlohmann::json::array();
  for (int i = 0; i < 8; ++i)
    for (int axis = 0; axis < 3; ++axis) vertices.push_back(static_cast<double>((i >> axis) & 1));
  const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                            {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (int f = 0; f < 12 - drop; ++f)
    for (const int c : faces[f]) triangles.push_back(c);
  return nlohmann::json{{"vertices", vertices}, {"triangles", triangles}}.dump();
}

TEST_F(CliTest, MeshConvertWritesTheCheckedMeshAsObjAndJson) {
  std::ofstream(dir_ / "cube.json") << cube_json();
  const fs::path obj = dir_ / "cube.obj";
  CommandRun r = uh(fmt::format("mesh convert '{}' -o '{}' --comment 'a unit cube'", (dir_ / "cube.json").string(),
                                obj.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("8 vertices, 12 triangles"), std::string::npos) << r.out;
  const std::string text = read_text(obj);
  EXPECT_EQ(text.rfind("# a unit cube\nv ", 0), 0u) << text;
  // the OBJ reads back as the same mesh: through the JSON again, and packed like any mesh
  const fs::path back = dir_ / "cube_back.json";
  r = uh(fmt::format("mesh convert '{}' -o '{}'", obj.string(), back.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(read_text(back));
  EXPECT_EQ(j["vertices"].size(), 24u);
  EXPECT_EQ(j["triangles"].size(), 36u);
  r = uh(fmt::format("ist build '{}' -o '{}' --spheres 30 --json", obj.string(), (dir_ / "cube.ist").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NEAR(json_of(r)["mesh_volume"].get<double>(), 1.0, 1e-12);
}

TEST_F(CliTest, MeshConvertRefusesAnOpenOrBrokenMeshNamingTheFileAndKeepsTheOutput) {
  const fs::path out = dir_ / "kept.obj";
  std::ofstream(out) << "an earlier file that must survive";
  std::ofstream(dir_ / "open_box.json") << cube_json(1);
  CommandRun r = uh(fmt::format("mesh convert '{}' -o '{}'", (dir_ / "open_box.json").string(), out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("open_box.json: mesh is not closed"), std::string::npos) << r.err;
  std::ofstream(dir_ / "bad_index.json") << R"({"vertices": [0, 0, 0, 1, 0, 0, 0, 1, 0], "triangles": [0, 1, 3]})";
  r = uh(fmt::format("mesh convert '{}' -o '{}'", (dir_ / "bad_index.json").string(), out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("bad_index.json: 'triangles[2]' is 3, not the index of one of the 3 vertices"),
            std::string::npos)
      << r.err;
  std::ofstream(dir_ / "ragged.json") << R"({"vertices": [0, 0, 0, 1], "triangles": []})";
  r = uh(fmt::format("mesh convert '{}' -o '{}'", (dir_ / "ragged.json").string(), out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("ragged.json: 'vertices' has 4 numbers, not x, y, z per vertex"), std::string::npos) << r.err;
  std::ofstream(dir_ / "cube.json") << cube_json();
  r = uh(fmt::format("mesh convert '{}' -o '{}'", (dir_ / "cube.json").string(), (dir_ / "cube.stl").string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("written as .obj or .json"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(out), "an earlier file that must survive");
}

TEST_F(CliTest, IstBuildRefusesAMeshStillOpenAfterRepairNamingAllowOpen) {
  const fs::path mesh = write_cube(dir_ / "holey.obj", true, "f 1 1 2\nf 1 3 2\n");
  const fs::path out = dir_ / "holey.ist";
  std::ofstream(out) << "an earlier file that must survive";
  const CommandRun r = uh(fmt::format("ist build '{}' -o '{}' --spheres 30", mesh.string(), out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("holey.obj: mesh is not closed after dropping 1 degenerate and 1 duplicate faces: 4 "
                       "boundary edges"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("--allow-open"), std::string::npos) << r.err;
  for (const char* cpp : {"MeshLoadOptions", "allow_open", "{.", "::"})
    EXPECT_EQ(r.err.find(cpp), std::string::npos) << cpp << " in " << r.err;
  EXPECT_EQ(read_text(out), "an earlier file that must survive");
  // with the option it builds, capping the hole, and says so
  const CommandRun open =
      uh(fmt::format("ist build '{}' -o '{}' --spheres 30 --allow-open --json", mesh.string(), out.string()));
  ASSERT_EQ(open.exit_code, 0) << open.err;
  const auto j = json_of(open);
  EXPECT_EQ(j["open_boundary_edges"], 4);
  EXPECT_EQ(j["repaired"]["degenerate_faces"], 1);
  EXPECT_NE(j["assumed"].get<std::string>().find("open mesh"), std::string::npos) << open.out;
  EXPECT_TRUE(collette::load_ist(out));
}

TEST_F(CliTest, NonManifoldMeshIsRefusedWithoutHintingAtAllowOpen) {
  // the repository's shared asset folder sits beside it (as the benchmarks read it)
  const fs::path shared = fs::path(UH_TEST_DATA_DIR).parent_path().parent_path() / "shared" / "assets";
  fs::path mesh = shared / "dragon_stanford_res4_11k_nonmanifold.ply";
  // the shared bad mesh when present; else a cube with a fin (a third face on one edge)
  if (!fs::exists(mesh)) mesh = write_cube(dir_ / "fin.obj", false, "v 0.5 -0.5 1.5\nf 5 6 10\n");
  const fs::path out = dir_ / "never_written.ist";
  const CommandRun r = uh(fmt::format("ist build '{}' -o '{}' --spheres 30", mesh.string(), out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(mesh.filename().string() + ": mesh is not 2-manifold"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("non-manifold edges"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("allow"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CliTest, BadInputGetsAnErrorNamingTheFileAndWritesNothing) {
  // an open box: one face missing
  const fs::path open_mesh = dir_ / "open_box.obj";
  {
    std::ofstream out(open_mesh);
    out << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
           "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\n";
  }
  const fs::path out = dir_ / "kept.ist";
  {
    std::ofstream keep(out);
    keep << "an earlier file that must survive";
  }
  const CommandRun r =
      uh(fmt::format("ist build '{}' -o '{}' --spheres 50", open_mesh.string(), out.string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("open_box.obj"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("boundary"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--allow-open"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(out), "an earlier file that must survive");

  // a corrupted .ist
  const fs::path broken = dir_ / "broken.ist";
  {
    std::string bytes = read_text(dir_ / "bunny.ist");
    bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x5a);
    std::ofstream(broken, std::ios::binary) << bytes;
  }
  const CommandRun info = uh(fmt::format("ist info '{}'", broken.string()));
  EXPECT_NE(info.exit_code, 0);
  EXPECT_NE(info.err.find("broken.ist"), std::string::npos) << info.err;

  // meaningless units with valid checksums: refused by every command that loads it, field named
  const fs::path negative = dir_ / "negative_units.ist";
  {
    auto asset = collette::load_ist(dir_ / "bunny.ist");
    ASSERT_TRUE(asset) << asset.error().message;
    asset->meta.meters_per_unit = -1.0;
    const auto bytes = collette::encode_ist(*asset);
    std::ofstream(negative, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  const CommandRun units = uh(fmt::format("ist info '{}'", negative.string()));
  EXPECT_NE(units.exit_code, 0);
  EXPECT_NE(units.err.find("negative_units.ist"), std::string::npos) << units.err;
  EXPECT_NE(units.err.find("meters_per_unit is -1"), std::string::npos) << units.err;
  const fs::path good_poses = write_poses(dir_ / "units_poses.csv", 2, 0.0, 0.1);
  const fs::path units_out = dir_ / "units.csv";
  const CommandRun uq =
      uh(fmt::format("query '{0}' '{1}' --poses '{2}' --out '{3}'", (dir_ / "bunny.ist").string(),
                     negative.string(), good_poses.string(), units_out.string()));
  EXPECT_NE(uq.exit_code, 0);
  EXPECT_NE(uq.err.find("meters_per_unit"), std::string::npos) << uq.err;
  EXPECT_FALSE(fs::exists(units_out));

  // a poses file without the quaternion columns
  const fs::path poses = dir_ / "bad_poses.csv";
  std::ofstream(poses) << "id,tx,ty,tz\na,0,0,0\n";
  const fs::path results = dir_ / "never.csv";
  const CommandRun q = uh(fmt::format("query '{0}' '{0}' --poses '{1}' --out '{2}'",
                                      (dir_ / "bunny.ist").string(), poses.string(), results.string()));
  EXPECT_NE(q.exit_code, 0);
  EXPECT_NE(q.err.find("bad_poses.csv"), std::string::npos) << q.err;
  EXPECT_NE(q.err.find("qw"), std::string::npos) << q.err;
  EXPECT_FALSE(fs::exists(results));

  // a field that is not a number: the message names the file, line and column
  const fs::path bad_number = dir_ / "bad_number.csv";
  std::ofstream(bad_number) << "# poses\nid,tx,ty,tz,qw,qx,qy,qz\na,0,0,0,1,0,0,0\nb,0,oops,0,1,0,0,0\n";
  const CommandRun n = uh(fmt::format("query '{0}' '{0}' --poses '{1}' --out '{2}'", (dir_ / "bunny.ist").string(),
                                      bad_number.string(), results.string()));
  EXPECT_NE(n.exit_code, 0);
  EXPECT_NE(n.err.find("bad_number.csv:4: column 'ty' (field 3) is 'oops', expected a finite number"), std::string::npos)
      << n.err;
  EXPECT_FALSE(fs::exists(results));
}

// A write that fails half-way (here at a file size limit, as on a full disk) leaves the earlier
// output whole and no temporary file behind.
TEST_F(CliTest, FailedWritesLeaveEarlierOutputsWhole) {
  const fs::path out_dir = dir_ / "limited";
  fs::create_directories(out_dir);
  const fs::path results = out_dir / "results.csv", ist = out_dir / "bunny.ist";
  std::ofstream(results) << "earlier results";
  std::ofstream(ist) << "earlier tree";
  const fs::path poses = write_poses(dir_ / "many_poses.csv", 400, -4.0, 2.0);
  // files of at most 16 blocks (8 KiB); SIGXFSZ ignored so that the write fails with EFBIG
  const std::string limit = "trap '' XFSZ; ulimit -f 16; ";

  const CommandRun q = uh(fmt::format("query '{0}' '{0}' --poses '{1}' --out '{2}'", (dir_ / "bunny.ist").string(),
                                      poses.string(), results.string()),
                          limit);
  EXPECT_NE(q.exit_code, 0);
  EXPECT_NE(q.err.find(results.string() + ": write failed: File too large"), std::string::npos) << q.err;
  EXPECT_EQ(read_text(results), "earlier results");

  const CommandRun b = uh(fmt::format("ist build '{}' -o '{}' --spheres 600", bunny().string(), ist.string()), limit);
  EXPECT_NE(b.exit_code, 0);
  EXPECT_NE(b.err.find(ist.string() + ": write failed: File too large"), std::string::npos) << b.err;
  EXPECT_EQ(read_text(ist), "earlier tree");

  int files = 0;
  for (const auto& e : fs::directory_iterator(out_dir)) files += e.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 2) << "no temporary file may be left behind";

  // without the limit both succeed and replace the files
  ASSERT_EQ(uh(fmt::format("query '{0}' '{0}' --poses '{1}' --out '{2}'", (dir_ / "bunny.ist").string(),
                           poses.string(), results.string()))
                .exit_code,
            0);
  EXPECT_EQ(read_text(results).rfind("id,volume,", 0), 0u);
}

// `uh devices` and `uh run --device` with the stand-in libdhd (tests/devices/standins/)
std::string with_standin(const fs::path& dir) {
  return fmt::format("UH_CACHE_DIR='{}' UH_FORCEDIMENSION_LIBRARY='{}' UH_OPENHAPTICS_LIBRARY='{}' ",
                     (dir / "cache").string(), UH_STANDIN_DHD, UH_STANDIN_HD);
}

// a small scene: the stylus on a simulated line through the bunny's middle. The tests that bind a
// stand-in device to it (with --device) find its handle resting inside the bunny, which the proxy,
// by design, leaves free until it comes out: they are about the device, so the scene renders on
// the penalty path.
fs::path write_small_device_scene(const fs::path& dir) {
  const fs::path meshes = fs::path(UH_TEST_DATA_DIR) / "meshes";
  std::ofstream(dir / "small.json") << fmt::format(R"({{
  "name": "small",
  "rates": {{ "haptic_hz": 1000, "collision_hz": 1000 }},
  "seconds": 0.5,
  "objects": [{{ "name": "bunny", "mesh": "{}", "meters_per_unit": 0.01, "spheres": 600,
               "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }} }}],
  "tool": {{ "name": "stylus", "mesh": "{}", "meters_per_unit": 0.01, "spheres": 150,
          "force": {{ "mode": "3dof", "stiffness": 1.6e4, "damping": 1.0, "max_force_n": 6.0 }},
          "device": {{ "driver": "sim-line", "config": {{ "start": [0, 0, 0.1], "end": [0, 0, 0.045] }} }} }},
  "watch": ["bunny"],
  "force": {{ "proxy": {{ "enabled": false }} }}
}})",
                                                   (meshes / "bunny_npm_3674.obj").string(),
                                                   (meshes / "stylus.obj").string());
  return dir / "small.json";
}

TEST_F(CliTest, DevicesListsWhereEachDriverLookedAndWhatItFound) {
  const CommandRun r = uh("devices --json", with_standin(dir_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const nlohmann::json* fd = nullptr;
  for (const auto& d : j["drivers"])
    if (d["driver"] == "forcedimension") fd = &d;
  ASSERT_NE(fd, nullptr) << r.out;
  EXPECT_EQ((*fd)["looked_for"][0]["path"], UH_STANDIN_DHD);
  EXPECT_EQ((*fd)["looked_for"][0]["from"], "UH_FORCEDIMENSION_LIBRARY");
  EXPECT_EQ((*fd)["loaded_from"], UH_STANDIN_DHD);
  ASSERT_EQ((*fd)["devices"].size(), 1u) << r.out;
  const auto& dev = (*fd)["devices"][0];
  EXPECT_EQ(dev["selector"], "forcedimension:0");
  EXPECT_EQ(dev["model"], "omega.3");
  EXPECT_EQ(dev["serial"], "11001");
  EXPECT_EQ(dev["dof_actuated"], 3);
  EXPECT_EQ(dev["max_force_n"], 12.0);
  EXPECT_EQ(dev["workspace_half_extents_m"][2], 0.055);
  const nlohmann::json* oh = nullptr;
  for (const auto& d : j["drivers"])
    if (d["driver"] == "openhaptics") oh = &d;
  ASSERT_NE(oh, nullptr) << r.out;
  EXPECT_EQ((*oh)["loaded_from"], UH_STANDIN_HD);
  ASSERT_EQ((*oh)["devices"].size(), 1u) << r.out;
  EXPECT_EQ((*oh)["devices"][0]["selector"], "openhaptics");
  EXPECT_EQ((*oh)["devices"][0]["model"], "Touch");
  EXPECT_EQ((*oh)["devices"][0]["max_force_n"], 3.3);

  // without the runtime: every place it looked, and why nothing was found
  const CommandRun none = uh("devices", "UH_FORCEDIMENSION_LIBRARY=/nonexistent/libdhd.so ");
  ASSERT_EQ(none.exit_code, 0) << none.err;
  EXPECT_NE(none.out.find("looked for /nonexistent/libdhd.so (from UH_FORCEDIMENSION_LIBRARY)"),
            std::string::npos)
      << none.out;
  EXPECT_NE(none.out.find("no device: could not load the Force Dimension DHD library"), std::string::npos)
      << none.out;
  EXPECT_NE(none.out.find("simulated (no hardware): sim-circle, sim-hand, sim-line, sim-raster, sim-replay"),
            std::string::npos)
      << none.out;
}

// the stand-in's handle rests at the origin, inside the bunny: a session with contact on it
TEST_F(CliTest, RunOnTheDeviceNamedOnTheCommandLine) {
  const fs::path scene = write_small_device_scene(dir_);
  const CommandRun r = uh(fmt::format("run '{}' --device forcedimension:0 --stepped --json", scene.string()),
                          with_standin(dir_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["haptic"]["ticks"], 500);
  EXPECT_GT(j["force"]["max_n"].get<double>(), 0.5);
  EXPECT_LE(j["force"]["max_n"].get<double>(), 6.0);
  // the report names the device, and DHD's communication rate (the stand-in's 1 kHz)
  EXPECT_EQ(j["device"]["driver"], "forcedimension");
  EXPECT_EQ(j["device"]["name"], "forcedimension omega.3");
  EXPECT_EQ(j["device"]["model"], "omega.3");
  EXPECT_EQ(j["device"]["serial"], "11001");
  EXPECT_EQ(j["device"]["com_rate_hz"], 1000.0);

  const CommandRun unknown =
      uh(fmt::format("run '{}' --device nope --stepped", scene.string()), with_standin(dir_));
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_EQ(
      unknown.err,
      "uh: --device: unknown driver 'nope' (known drivers: forcedimension, haply, openhaptics, sim-circle, "
      "sim-hand, sim-line, "
      "sim-raster, sim-replay)\n");
  const CommandRun missing = uh(
      fmt::format("run '{}' --device forcedimension:serial=4 --stepped", scene.string()), with_standin(dir_));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("tool.device: forcedimension: no device with serial 4 (found: serial 11001)"),
            std::string::npos)
      << missing.err;
}

// the loopback Inverse Service (tests/devices/standins/) on a thread of this test, uh a child
// process that finds it through UH_HAPLY_URL; its cursor rests at the origin, inside the bunny
TEST_F(CliTest, DevicesAndRunOnHaplysService) {
  devices::testing::HaplyStandinService service;
  const std::string env = with_standin(dir_) + fmt::format("UH_HAPLY_URL='{}' ", service.url());
  const CommandRun listed = uh("devices --json", env);
  ASSERT_EQ(listed.exit_code, 0) << listed.err;
  const auto j = nlohmann::json::parse(listed.out);
  const nlohmann::json* haply = nullptr;
  for (const auto& d : j["drivers"])
    if (d["driver"] == "haply") haply = &d;
  ASSERT_NE(haply, nullptr) << listed.out;
  EXPECT_EQ((*haply)["runtime"], "Haply Inverse Service");
  EXPECT_EQ((*haply)["looked_for"][0]["path"], service.url());
  EXPECT_EQ((*haply)["looked_for"][0]["from"], "UH_HAPLY_URL");
  EXPECT_EQ((*haply)["loaded_from"], service.url());
  ASSERT_EQ((*haply)["devices"].size(), 1u) << listed.out;
  const auto& dev = (*haply)["devices"][0];
  EXPECT_EQ(dev["selector"], "haply:049D");
  EXPECT_EQ(dev["model"], "Inverse3");
  EXPECT_EQ(dev["serial"], "049D");
  EXPECT_EQ(dev["dof_actuated"], 3);
  EXPECT_EQ(dev["max_force_n"], 2.0);
  const CommandRun text = uh("devices", env);
  EXPECT_NE(text.out.find(fmt::format("  connected to {}\n", service.url())), std::string::npos) << text.out;
  EXPECT_NE(
      text.out.find("  haply:049D  Inverse3, serial 049D: 3-DOF sensed, 3-DOF force, max 2.0 N, workspace "
                    "not reported, rate set by the client\n"),
      std::string::npos)
      << text.out;

  // a threaded session clocked by the service's replies, with contact
  const fs::path scene = write_small_device_scene(dir_);
  const CommandRun r = uh(fmt::format("run '{}' --device haply --seconds 0.3 --json", scene.string()), env);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto run = nlohmann::json::parse(r.out);
  EXPECT_GT(run["haptic"]["ticks"].get<int>(), 100);
  EXPECT_GT(run["haptic"]["rate_hz"].get<double>(), 0.0);
  EXPECT_GT(run["force"]["max_n"].get<double>(), 0.5);
  EXPECT_LE(run["force"]["max_n"].get<double>(), 2.0);  // the device's limit, below the tool's 6 N
  EXPECT_EQ(run["device"]["driver"], "haply");
  EXPECT_EQ(run["device"]["name"], "haply Inverse3 049D");
  EXPECT_EQ(run["device"]["serial"], "049D");

  // the service fails mid-run: the session ends at once with the device and the service's words
  devices::testing::HaplyStandinScript failing;
  failing.fault = devices::testing::HaplyFault::kError;
  failing.fault_after = 100;
  service.set_script(failing);
  const CommandRun failed =
      uh(fmt::format("run '{}' --device haply:device_id=049D --seconds 30", scene.string()), env);
  EXPECT_EQ(failed.exit_code, 1);
  EXPECT_NE(
      failed.err.find("device 'haply Inverse3 049D' faulted: the service reported an error: Inverse3 049D: "
                      "the motors are too hot; it was sent zero force"),
      std::string::npos)
      << failed.err;
  EXPECT_EQ(service.received().back(), Vec3{});
}

// two devices of different drivers in one session, each on its stand-in: HD's Touch presses into
// the bunny (its handle rests at the origin), the omega.3 into a ball 15 cm beside it (its
// workspace moved there); HD's scheduler clocks one loop, the manager's own the other. Each handle
// rests inside its object, which the proxy leaves free until it comes out: the penalty path.
TEST_F(CliTest, RunsTwoDevicesOfDifferentDriversInOneSession) {
  const fs::path meshes = fs::path(UH_TEST_DATA_DIR) / "meshes";
  const fs::path scene = dir_ / "hands.json";
  std::ofstream(scene) << fmt::format(R"({{
  "name": "hands",
  "seconds": 0.3,
  "objects": [{{ "name": "bunny", "mesh": "{0}", "meters_per_unit": 0.01, "spheres": 600,
               "pose": {{ "position": [0, 0, 0], "rotation": [0.70710678, 0.70710678, 0, 0] }} }},
             {{ "name": "ball", "mesh": "{1}", "meters_per_unit": 0.03, "spheres": 200,
               "pose": {{ "position": [0.15, 0, 0.03] }} }}],
  "tools": [{{ "name": "left", "mesh": "{2}", "meters_per_unit": 0.01, "spheres": 150,
             "force": {{ "mode": "3dof", "stiffness": 1.6e4, "damping": 1.0, "max_force_n": 6.0 }},
             "device": {{ "driver": "openhaptics" }} }},
            {{ "name": "right", "mesh": "{2}", "meters_per_unit": 0.01, "spheres": 150,
             "force": {{ "mode": "3dof", "stiffness": 1.6e4, "damping": 1.0, "max_force_n": 6.0 }},
             "device": {{ "driver": "forcedimension", "config": {{ "serial": 11001 }} }},
             "workspace": {{ "offset": [0.15, 0, 0.03] }} }}],
  "force": {{ "proxy": {{ "enabled": false }} }}
}})",
                                      (meshes / "bunny_npm_3674.obj").string(),
                                      (meshes / "ball.obj").string(), (meshes / "stylus.obj").string());
  const CommandRun r = uh(fmt::format("run '{}' --json", scene.string()), with_standin(dir_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["tools"].size(), 2u) << r.out;
  const auto& left = j["tools"][0];
  const auto& right = j["tools"][1];
  EXPECT_EQ(left["tool"], "left");
  EXPECT_EQ(left["device"]["name"], "openhaptics Touch");
  EXPECT_EQ(right["device"]["name"], "forcedimension omega.3");
  EXPECT_EQ(right["device"]["serial"], "11001");
  for (const auto* t : {&left, &right}) {
    EXPECT_GT((*t)["haptic"]["ticks"].get<int>(), 100) << *t;
    EXPECT_GT((*t)["contact"]["ticks"].get<int>(), 50) << *t;
    EXPECT_GT((*t)["force"]["max_n"].get<double>(), 0.5) << *t;
    EXPECT_EQ((*t)["force"]["nonfinite"], 0) << *t;
  }
  EXPECT_LE(left["force"]["max_n"].get<double>(), 3.3) << "the Touch's own limit";
  EXPECT_LE(right["force"]["max_n"].get<double>(), 6.0) << "the tool's limit, below the omega.3's 12 N";
  EXPECT_EQ(j["device"], left["device"]) << "the top level is the first tool's, as in one-tool sessions";

  // the summary has a block per device
  const CommandRun text = uh(fmt::format("run '{}' --seconds 0.2", scene.string()), with_standin(dir_));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("device    tool 'left': openhaptics Touch"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("device    tool 'right': forcedimension omega.3, serial 11001"), std::string::npos)
      << text.out;
  // --device names one device: refused for two
  const CommandRun refused =
      uh(fmt::format("run '{}' --device forcedimension --seconds 0.2", scene.string()), with_standin(dir_));
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.err.find("--device replaces the device of a one-tool scene; this scene has 2 tools"),
            std::string::npos)
      << refused.err;
}

// ---- uh explore: the materials of scenes/materials.json recovered from the force trace ----
//
// References from the scene file itself (not from the estimators) and textbook geometry: a ball
// of radius r pressed into a sphere of radius R under the gradient law feels k times the contact
// disk's area, pi a^2 with a^2 = 2 r_eff d - ... (r_eff = r R / (r + R)), so its stiffness at first
// touch is 2 pi r_eff k; on a curved surface a grating of period P passes under the contact point
// while the tool's centre travels (R + r) / R times as far.

struct MaterialsScene {
  nlohmann::json scene;
  nlohmann::json material(const std::string& object) const {
    // (operator[] on a const json with a missing key is undefined: an object without a material reads
    // as an empty one)
    for (const auto& o : scene.at("objects"))
      if (o.at("name") == object) {
        if (!o.contains("material")) return nlohmann::json::object();
        const nlohmann::json& m = o.at("material");
        return m.is_string() ? scene.at("materials").at(m.get<std::string>()) : m;
      }
    ADD_FAILURE() << "no object " << object;
    return {};
  }
  double radius(const std::string& object) const {
    for (const auto& o : scene["objects"])
      if (o["name"] == object) return o["meters_per_unit"].get<double>();  // ball_fine.obj has radius 1
    return 0.0;
  }
  double tool_radius() const { return scene["tool"]["meters_per_unit"].get<double>(); }
  double stiffness(const std::string& object) const {
    const auto m = material(object);
    return m.contains("stiffness") ? m["stiffness"].get<double>()
                                   : scene["tool"]["force"]["stiffness"].get<double>();
  }
};

fs::path materials_scene_path() {
  return fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials.json";
}

MaterialsScene materials_scene() {
  std::ifstream in(materials_scene_path());
  return {nlohmann::json::parse(in)};
}

nlohmann::json explored(const nlohmann::json& out, const std::string& object) {
  for (const auto& o : out["objects"])
    if (o["name"] == object) return o;
  ADD_FAILURE() << "not explored: " << object;
  return {};
}

// What `uh explore` reads through the proxy (the default) for a material whose spring is
// `material_n_per_mm`: the material's, or, where the material is stiffer than the device renders
// passively, that limit, and it says so. The scenes' coupling asks 1.5 kN/m, within the passive
// bound for the device's damping at 1 kHz (0.9 x 2 b / T = 1.8 kN/m at b = 1 N s/m).
void expect_rendered_stiffness(const nlohmann::json& e, double material_n_per_mm, const std::string& what) {
  ASSERT_TRUE(e["rendered_stiffness_limit_n_per_mm"].is_number()) << what << ": explored through the proxy";
  const double limit = e["rendered_stiffness_limit_n_per_mm"].get<double>();
  EXPECT_NEAR(limit, 1.5, 1e-9) << what;
  const double expected = std::min(material_n_per_mm, limit);
  EXPECT_NEAR(e["stiffness_n_per_mm"].get<double>(), expected, 0.05 * expected) << what;
  EXPECT_EQ(e["stiffness_is_rendered_limit"].get<bool>(), material_n_per_mm > limit) << what;
}

// On the penalty path, which renders each material as it is: its damping, its textures as the contact
// point feels them and springs stiffer than the proxy's passive limit (expect_rendered_stiffness).
TEST_F(CliTest, ExploreRecoversEveryMaterialOfTheMaterialsScene) {
  const MaterialsScene scene = materials_scene();
  const CommandRun r = uh(fmt::format("explore '{}' --proxy off --json", materials_scene_path().string()),
                          fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = json_of(r);
  ASSERT_EQ(out["objects"].size(), scene.scene["objects"].size());
  const double r_tool = scene.tool_radius();

  // stiffness within 5 %: flat (1 m spheres) and curved (the 4 cm dome)
  for (const std::string object : {"stiff", "soft", "dome"}) {
    const double big = scene.radius(object);
    const double r_eff = r_tool * big / (r_tool + big);
    const double reference = 2.0 * kPi * r_eff * scene.stiffness(object) * 1e-3;  // N/mm
    EXPECT_NEAR(explored(out, object)["stiffness_n_per_mm"].get<double>(), reference, 0.05 * reference)
        << object;
  }
  // the stiff one feels stiffer than the soft one, by their ratio
  EXPECT_NEAR(explored(out, "stiff")["stiffness_n_per_mm"].get<double>() /
                  explored(out, "soft")["stiffness_n_per_mm"].get<double>(),
              scene.stiffness("stiff") / scene.stiffness("soft"),
              0.05 * scene.stiffness("stiff") / scene.stiffness("soft"));

  // friction within 10 % (flat and curved); frictionless surfaces read near zero
  for (const std::string object : {"sticky", "slippery", "dome"}) {
    const auto m = scene.material(object)["friction"];
    const auto e = explored(out, object);
    EXPECT_NEAR(e["friction_static"].get<double>(), m["static"].get<double>(),
                0.1 * m["static"].get<double>())
        << object;
    EXPECT_NEAR(e["friction_dynamic"].get<double>(), m["dynamic"].get<double>(),
                0.1 * m["dynamic"].get<double>())
        << object;
  }
  for (const std::string object : {"stiff", "soft", "ridged", "rough"}) {
    EXPECT_LT(explored(out, object)["friction_static"].get<double>(), 0.06) << object;
    EXPECT_LT(explored(out, object)["friction_dynamic"].get<double>(), 0.02) << object;
  }

  // texture period within 5 % (on the curved dome: the period the tool's centre travels)
  const double ridged_period = scene.material("ridged")["texture"]["period"].get<double>();
  const double flat_factor = (scene.radius("ridged") + r_tool) / scene.radius("ridged");
  EXPECT_NEAR(explored(out, "ridged")["texture_period_m"].get<double>(), ridged_period * flat_factor,
              0.05 * ridged_period);
  const double dome_period = scene.material("dome")["texture"]["period"].get<double>() *
                             (scene.radius("dome") + r_tool) / scene.radius("dome");
  EXPECT_NEAR(explored(out, "dome")["texture_period_m"].get<double>(), dome_period, 0.05 * dome_period);
  // smooth surfaces have no period and hardly any ripple; textured ones ripple
  for (const std::string object : {"stiff", "soft", "sticky", "slippery"}) {
    EXPECT_TRUE(explored(out, object)["texture_period_m"].is_null()) << object;
    EXPECT_LT(explored(out, object)["texture_ripple_n"].get<double>(), 0.002) << object;
  }
  for (const std::string object : {"ridged", "rough", "dome"})
    EXPECT_GT(explored(out, object)["texture_ripple_n"].get<double>(), 0.01) << object;
  // the random texture ripples but has no period: no one wave explains its contour
  EXPECT_TRUE(explored(out, "rough")["texture_period_m"].is_null()) << explored(out, "rough");

  // damping: the soft material (resin) has 0.5 N s/m, read from the loops between each press and
  // its release; the other untextured ones none (on these smooth faces every pair's normal is
  // the contact normal, so the felt damping is the material's)
  const double resin_damping = scene.material("soft")["damping"].get<double>();
  EXPECT_NEAR(explored(out, "soft")["damping_n_s_per_m"].get<double>(), resin_damping, 0.05 * resin_damping);
  for (const std::string object : {"stiff", "sticky", "slippery"})
    EXPECT_NEAR(explored(out, object)["damping_n_s_per_m"].get<double>(), 0.0, 0.01) << object;

  // passivity over each whole (closed) exploration: friction and damping take energy out, the
  // texture's passivity controller lets at most a tick's worth in
  for (const auto& o : out["objects"]) {
    EXPECT_LT(o["work_on_hand_j"].get<double>(), 1e-3) << o["name"];
    EXPECT_LT(o["simulated_s"].get<double>(), 36.0) << o["name"] << ": the script ran to its end";
  }
  EXPECT_LT(explored(out, "sticky")["work_on_hand_j"].get<double>(), -0.01) << "friction dissipates";
}

// A dome's exploration `e` through the proxy: its `material`'s friction within 10 %, the grating's
// `period` (the tool centre's) within 5 %, and passivity
void expect_dome_friction_and_grating(const nlohmann::json& e, const nlohmann::json& material, double period,
                                      const std::string& label) {
  for (const std::string coefficient : {"static", "dynamic"})
    EXPECT_NEAR(e["friction_" + coefficient].get<double>(), material["friction"][coefficient].get<double>(),
                0.1 * material["friction"][coefficient].get<double>())
        << label << " " << coefficient;
  ASSERT_TRUE(e["texture_period_m"].is_number()) << label << ": " << e;
  EXPECT_NEAR(e["texture_period_m"].get<double>(), period, 0.05 * period) << label;
  EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << label << ": passive";
}

// Through the proxy on the curved dome (k = 3e4, friction and a grating at once): each stroke breaks
// away uphill on its flank, so the breakaway is read in the surface's frame, not the hand's motion's
// (read in that frame it was 0.67 for 0.5). Friction within 10 % and the grating's period within 5 %
// of the path the tool's centre travels: read along the hand's path, a millimetre under the proxy,
// it was 2.96 mm for 3.13 at seed 1; along the tool's path with its relief and, at 10 kHz, its slides
// between the proxy's steps, 3.37 mm.
TEST_F(CliTest, ExploreReadsTheDomesFrictionAndGratingThroughTheProxy) {
  const MaterialsScene scene = materials_scene();
  const double period = scene.material("dome")["texture"]["period"].get<double>() *
                        (scene.radius("dome") + scene.tool_radius()) / scene.radius("dome");
  for (const std::string seed : {"1", "2", "1 --haptic-hz 10000 --ticks-per-collision 10"}) {
    const CommandRun r = uh(
        fmt::format("explore '{}' --object dome --seed {} --json", materials_scene_path().string(), seed),
                            fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    expect_dome_friction_and_grating(json_of(r)["objects"][0], scene.material("dome"), period, "seed " + seed);
  }
}

// The dome ten times softer (k = 3e3) and packed with 10,000 spheres, through the proxy: the device's
// spring is 0.19 N/mm, so the hand holding 2 N presses 10 mm under the tool and, on the curve, slides on
// a line the tool does not follow; friction opposes the tool's motion (the proxy's, the handle plus
// the force over that spring), and read in the hand's motion the dynamic friction was 0.23 for 0.35.
// The grating's period within 5 %: the hand seats and lets go within half a second whatever the
// spring (at the press speed, 10.6 mm each way took 24 s and the 40 s budget ended before the
// contour), and the contour's ripple is read along the normal (the force across the motion leans
// with the soft spring: the wave share was 0.10-0.78 at seeds 1-4, now 0.74-0.89 beyond chance).
TEST_F(CliTest, ExploreReadsASoftDomesFrictionAndGratingThroughTheProxy) {
  MaterialsScene scene = materials_scene();
  nlohmann::json dome;
  for (const auto& o : scene.scene["objects"])
    if (o["name"] == "dome") dome = o;
  const fs::path assets = materials_scene_path().parent_path();
  dome["mesh"] = (assets / dome["mesh"].get<std::string>()).string();
  dome["spheres"] = 10000;
  dome["material"]["stiffness"] = 3000.0;
  scene.scene["objects"] = nlohmann::json::array({dome});
  scene.scene["tool"]["mesh"] = (assets / scene.scene["tool"]["mesh"].get<std::string>()).string();
  const fs::path path = dir_ / "soft_dome.json";
  std::ofstream(path) << scene.scene.dump(1);
  const double period = dome["material"]["texture"]["period"].get<double>() *
                        (scene.radius("dome") + scene.tool_radius()) / scene.radius("dome");
  for (const int seed : {2, 4}) {
    const CommandRun r = uh(fmt::format("explore '{}' --seed {} --json", path.string(), seed),
                            fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json e = json_of(r)["objects"][0];
    expect_dome_friction_and_grating(e, dome["material"], period, fmt::format("seed {}", seed));
    EXPECT_LT(e["simulated_s"].get<double>(), 36.0) << "seed " << seed << ": the script ran to its end";
  }
}

// A random texture (l = 1 mm) read through the proxy has no period, as on the penalty path: the
// relief rendered whole lets its slow waves fit the contour in any direction, and the best of the
// strokes' candidates explained 0.62 of it at seed 2 (3.77 mm on the 1 m ball, 6.27 mm on the flat
// slab). Its decision measure, the wave share beyond the best the same search finds turned to
// other directions, stays 0.1 or more under the 0.25 a period needs (measured at most 0.11 at seeds
// 1-8; with the median of single turned waves as the chance it reached 0.40-0.41 at seed 2).
TEST_F(CliTest, ExploreReadsNoPeriodInARandomTextureThroughTheProxy) {
  const fs::path flat = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_flat.json";
  for (const fs::path& path : {materials_scene_path(), flat}) {
    for (const int seed : {1, 2, 3, 4}) {
      const CommandRun r = uh(fmt::format("explore '{}' --object rough --seed {} --json", path.string(), seed),
                              fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const nlohmann::json e = json_of(r)["objects"][0];
      ASSERT_TRUE(e["rendered_stiffness_limit_n_per_mm"].is_number()) << "explored through the proxy";
      EXPECT_GT(e["texture_ripple_n"].get<double>(), 0.01) << path << " seed " << seed << ": it ripples";
      EXPECT_TRUE(e["texture_period_m"].is_null()) << path << " seed " << seed << ": " << e;
      EXPECT_LT(e["texture_wave_share"].get<double>(), 0.15) << path << " seed " << seed << ": the margin";
    }
  }
}

// The flat slab's 2 mm grating at the softest stiffness the docs explore (k = 3e3: the device's
// spring 0.19 N/mm, the grating's ripple 0.013 N), through the proxy: its period within 5 % at every
// seed with a wave share 0.1 or more above the 0.25 needed (measured 0.63-0.83 at seeds 1-8). At
// seed 2 one axis runs nearly along the ridges and its strokes ripple 0.78 as much as the other's
// (0.010 N: the grating's slow component the cubic leaves); the axis's component was searched on the
// contour only under 0.6, and the pair of peaks (2.03 and 4.59 mm) gave 1.86 mm: no period. Each
// axis whose strokes' ripple is mostly one sinusoid now has its other component searched.
TEST_F(CliTest, ExploreReadsASoftFlatSlabsGratingAtEverySeedThroughTheProxy) {
  const fs::path flat = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_flat.json";
  std::ifstream in(flat);
  MaterialsScene scene{nlohmann::json::parse(in)};
  nlohmann::json ridged;
  for (const auto& o : scene.scene["objects"])
    if (o["name"] == "ridged") ridged = o;
  ridged["mesh"] = (flat.parent_path() / ridged["mesh"].get<std::string>()).string();
  ridged["material"]["stiffness"] = 3000.0;
  scene.scene["objects"] = nlohmann::json::array({ridged});
  const std::string tool_mesh = scene.scene["tool"]["mesh"].get<std::string>();
  scene.scene["tool"]["mesh"] = (flat.parent_path() / tool_mesh).string();
  const fs::path path = dir_ / "soft_slab.json";
  std::ofstream(path) << scene.scene.dump(1);
  const double period = ridged["material"]["texture"]["period"].get<double>();
  for (const int seed : {1, 2, 3, 4, 5, 6}) {
    const CommandRun r = uh(fmt::format("explore '{}' --seed {} --json", path.string(), seed),
                            fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json e = json_of(r)["objects"][0];
    ASSERT_TRUE(e["texture_period_m"].is_number()) << "seed " << seed << ": " << e;
    EXPECT_NEAR(e["texture_period_m"].get<double>(), period, 0.05 * period) << "seed " << seed;
    EXPECT_GT(e["texture_wave_share"].get<double>(), 0.35) << "seed " << seed << ": the margin";
    EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << "seed " << seed << ": passive";
  }
}

TEST_F(CliTest, ExploreFindsTheTexturePeriodAtTenKilohertzToo) {
  const MaterialsScene scene = materials_scene();
  const CommandRun r = uh(
      fmt::format("explore '{}' --object ridged --haptic-hz 10000 --ticks-per-collision 10 --seed 3 --json",
                  materials_scene_path().string()),
      fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = json_of(r);
  ASSERT_EQ(out["objects"].size(), 1u);
  const double period = scene.material("ridged")["texture"]["period"].get<double>() *
                        (scene.radius("ridged") + scene.tool_radius()) / scene.radius("ridged");
  EXPECT_NEAR(out["objects"][0]["texture_period_m"].get<double>(), period, 0.05 * period);
  EXPECT_GT(out["objects"][0]["haptic_ticks"].get<double>(), 50000.0) << "10 kHz";
  EXPECT_LT(out["objects"][0]["work_on_hand_j"].get<double>(), 1e-3);
}

// Friction on a flat face (`e` explored `material`'s): the dynamic within 10 %, the static within 5 %,
// as it reads on both paths since the breakaway's frame is fitted against position (fitted against
// the distance travelled, a degree and a half off, it read 0.56 for 0.6)
void expect_flat_friction(const nlohmann::json& e, const nlohmann::json& friction, const std::string& label) {
  EXPECT_NEAR(e["friction_static"].get<double>(), friction["static"].get<double>(),
              0.05 * friction["static"].get<double>())
      << label << " static";
  EXPECT_NEAR(e["friction_dynamic"].get<double>(), friction["dynamic"].get<double>(),
              0.1 * friction["dynamic"].get<double>())
      << label << " dynamic";
}

// An exploration `e` of the flat slab's object: the grating's period within 5 % on the ridged one,
// else the material's friction (expect_flat_friction)
void expect_grating_or_friction(const MaterialsScene& scene, const nlohmann::json& e, const std::string& label) {
  const std::string object = e["name"].get<std::string>();
  if (object == "ridged") {
    const double period = scene.material(object)["texture"]["period"].get<double>();
    ASSERT_TRUE(e["texture_period_m"].is_number()) << label << ": " << e;
    EXPECT_NEAR(e["texture_period_m"].get<double>(), period, 0.05 * period) << label;
    return;
  }
  expect_flat_friction(e, scene.material(object)["friction"], label);
}

// The flat slab (a packed box, scenes/materials_flat.json): stiffness within 5 % (a ball on a
// plane: 2 pi r k at first touch), friction within 10 % and the grating's period within 5 % on a
// flat packed face as on the round ones, at 1 and 10 kHz; the packing's grain (its spheres' caps
// under the face) reads as neither friction nor a period, nor does the random texture. One
// packing, cached between the runs. On the penalty path, as ExploreRecoversEveryMaterialOfTheMaterialsScene.
TEST_F(CliTest, ExploreRecoversEveryMaterialOnAFlatPackedSlab) {
  const fs::path path = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_flat.json";
  std::ifstream in(path);
  const MaterialsScene scene{nlohmann::json::parse(in)};
  for (const std::string run : {"sticky", "slippery", "plain", "stiff", "rough", "ridged",
                                "ridged --haptic-hz 10000 --ticks-per-collision 10 --seed 2"}) {
    const CommandRun r = uh(fmt::format("explore '{}' --proxy off --object {} --json", path.string(), run),
                            fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json e = json_of(r)["objects"][0];
    const std::string object = e["name"].get<std::string>();
    EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << run << ": passive";
    if (object != "ridged" && object != "rough") {  // a texture's heights move the press too
      const double reference = 2.0 * kPi * scene.tool_radius() * scene.stiffness(object) * 1e-3;  // N/mm
      EXPECT_NEAR(e["stiffness_n_per_mm"].get<double>(), reference, 0.05 * reference) << run;
    }
    // the damping felt: the stiff slab's material has 1 N s/m along the normal, which the law's
    // pairs feel times their overlap-weighted mean cos^2 to the face normal (0.87-0.89 on this
    // packing); the others have none
    if (object == "stiff") {
      EXPECT_NEAR(e["damping_n_s_per_m"].get<double>(), 0.85 * scene.material(object)["damping"].get<double>(),
                  0.05)
          << run;
      continue;
    }
    if (object == "plain" || object == "sticky" || object == "slippery") {
      EXPECT_NEAR(e["damping_n_s_per_m"].get<double>(), 0.0, 0.02) << run << ": no damping";
    }
    if (object == "plain" || object == "rough") {
      EXPECT_LT(e["friction_static"].get<double>(), 0.06) << run << ": the grain is no friction";
      EXPECT_LT(e["friction_dynamic"].get<double>(), 0.02) << run << ": the grain is no friction";
      EXPECT_TRUE(e["texture_period_m"].is_null()) << run << ": " << e;
      continue;
    }
    expect_grating_or_friction(scene, e, run);
  }
}

// Friction on the 6-DOF proxy (scenes/materials_packed.json: a block packed with 10,000 spheres of
// unbounded radius, as a user's own mesh would be): `uh explore` reads each material's static friction
// within 5 % and its dynamic within 10 %, and the packing's grain as no friction. Measured at seed 1:
// 0.597 / 0.400 for 0.6 / 0.4, 0.246 / 0.150 for 0.25 / 0.15, 0.002 / 0.002 on the plain block.
TEST_F(CliTest, ExploreReadsFrictionThroughTheProxyOnAPackedBlock) {
  const fs::path path = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_packed.json";
  std::ifstream in(path);
  const nlohmann::json scene = nlohmann::json::parse(in);
  ASSERT_TRUE(scene["force"]["proxy"]["enabled"].get<bool>());
  const CommandRun r = uh(fmt::format("explore '{}' --json", path.string()),
                          fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = json_of(r);
  ASSERT_EQ(out["objects"].size(), scene["objects"].size());
  for (std::size_t i = 0; i < scene["objects"].size(); ++i) {
    const nlohmann::json& object = scene["objects"][i];
    const nlohmann::json& e = out["objects"][i];
    EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << object["name"] << ": passive";
    if (!object.contains("material")) {
      EXPECT_LT(e["friction_static"].get<double>(), 0.03) << "the grain is no friction";
      EXPECT_LT(e["friction_dynamic"].get<double>(), 0.02) << "the grain is no friction";
      continue;
    }
    expect_flat_friction(e, object["material"]["friction"], object["name"].get<std::string>());
  }
}

// Through the proxy (the default), which rests on the slab's mesh (scenes/materials_flat.json, packed
// with 20,000 spheres): friction within 10 %, the grating's period within 5 % and its whole relief; before the proxy
// rested on the mesh in `uh explore`, its spheres' grain hid the grating (no period) and a tool
// starting over a coarse packing began inside the mesh (0.42 N/mm for 1.25).
TEST_F(CliTest, ExploreReadsFrictionAndAGratingThroughTheProxyOnAFlatPackedSlab) {
  const fs::path path = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_flat.json";
  std::ifstream in(path);
  const MaterialsScene scene{nlohmann::json::parse(in)};
  for (const std::string object : {"sticky", "slippery", "ridged"}) {
    const CommandRun r = uh(fmt::format("explore '{}' --object {} --json", path.string(), object),
                            fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json e = json_of(r)["objects"][0];
    EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << object << ": passive";
    expect_grating_or_friction(scene, e, object);
    if (object == "ridged") {
      // the tool rides the whole relief: the device's spring times the grating's RMS height (0.088 N;
      // 0.080 N measured; 0.037 N when the packing's rows, each raised at its own point, held it up)
      const double amplitude = scene.material(object)["texture"]["amplitude"].get<double>();
      const double spring = e["stiffness_n_per_mm"].get<double>() * 1e3;
      EXPECT_GT(e["texture_ripple_n"].get<double>(), 0.75 * spring * amplitude / std::sqrt(2.0)) << e;
    }
  }
}

// A 2 cm block packed with spheres of bounded radius (unbounded, its face reads 9-33 % soft): the
// material's stiffness on the penalty path; through the proxy, the same below its passive limit,
// the limit above it.
TEST_F(CliTest, ExploreRecoversTheStiffnessOfAThickPackedBlock) {
  const fs::path path = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_block.json";
  std::ifstream in(path);
  const nlohmann::json scene = nlohmann::json::parse(in);
  const double tool_radius = scene["tool"]["meters_per_unit"].get<double>();  // ball.obj has radius 1
  for (const auto& object : scene["objects"]) {
    ASSERT_TRUE(object.contains("max_sphere_radius")) << object;
    const double k = object.contains("material") ? object["material"]["stiffness"].get<double>()
                                                 : scene["tool"]["force"]["stiffness"].get<double>();
    const std::string name = object["name"].get<std::string>();
    const double reference = 2.0 * kPi * tool_radius * k * 1e-3;  // N/mm
    for (const std::string path_option : {"--proxy off", ""}) {
      const CommandRun r =
          uh(fmt::format("explore '{}' {} --object {} --json --seed 1", path.string(), path_option, name),
             fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const nlohmann::json e = json_of(r)["objects"][0];
      if (path_option.empty()) {
        expect_rendered_stiffness(e, reference, name);
      } else {
        EXPECT_NEAR(e["stiffness_n_per_mm"].get<double>(), reference, 0.05 * reference) << name;
        EXPECT_TRUE(e["rendered_stiffness_limit_n_per_mm"].is_null()) << name << ": the penalty path";
      }
      EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << name << " " << path_option << ": passive";
    }
  }
}

// Surfaces as stiff as the museum's materials (k = 1.5e5 and 2.5e5 N/m^2), flat and curved: a press
// to 2.5 mm asks up to 40 N of the 1 cm ball, which the scene's tool and safety limits allow; the
// presses reach their depth (a press stopped short by the force reads a packed face low) and the
// stiffness is recovered within 5 % at every seed on the penalty path. Through the proxy (the
// default) each reads the device's passive limit, and `uh explore` says that it is not the material's.
TEST_F(CliTest, ExploreRecoversTheStiffnessOfStiffSurfaces) {
  const fs::path path = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes" / "materials_stiff.json";
  std::ifstream in(path);
  const MaterialsScene scene{nlohmann::json::parse(in)};
  const double r = scene.tool_radius();
  const std::string cache = fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string());
  for (const int seed : {1, 2, 3, 4, 0}) {  // 0: seed 1 through the proxy
    const std::string path_option = seed == 0 ? "" : "--proxy off";
    const CommandRun run =
        uh(fmt::format("explore '{}' {} --json --seed {}", path.string(), path_option, std::max(seed, 1)), cache);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const nlohmann::json out = json_of(run);
    ASSERT_EQ(out["objects"].size(), scene.scene["objects"].size());
    for (const auto& object : scene.scene["objects"]) {
      const std::string name = object["name"].get<std::string>();
      const nlohmann::json e = explored(out, name);
      const double k = scene.stiffness(name);
      EXPECT_GE(k, 1.5e5) << name << ": as stiff as the museum's materials";
      // the block's face is flat; ball_fine.obj has radius 1, so a ball's radius is its meters_per_unit
      const bool ball = object["mesh"].get<std::string>().ends_with("ball_fine.obj");
      const double r_eff = ball ? r * scene.radius(name) / (r + scene.radius(name)) : r;
      const double reference = 2.0 * kPi * r_eff * k * 1e-3;  // N/mm
      if (seed == 0) {
        expect_rendered_stiffness(e, reference, name);
        EXPECT_LT(e["work_on_hand_j"].get<double>(), 1e-3) << name << ": passive";
        continue;
      }
      EXPECT_NEAR(e["stiffness_n_per_mm"].get<double>(), reference, 0.05 * reference)
          << name << " seed " << seed;
      EXPECT_GT(e["press_reach_m"].get<double>(), 0.0024)
          << name << " seed " << seed << ": pressed 2.5 mm in";
      // passive but for a sampled spring's leak: the force a tick sends lags the hand by the
      // surface's stiffness times the travel in a tick (at most 1.2 times the reference at 2.5 mm
      // under a packed face), over the 2.5 mm in and out of each of the five presses
      const double leak = 5 * 2 * 1.2 * reference * 1e3 * 0.004 * 0.001 * 0.0025;  // J
      EXPECT_LT(e["work_on_hand_j"].get<double>(), leak) << name << ": passive";
    }
  }
  const std::string name = scene.scene["objects"][0]["name"].get<std::string>();
  const CommandRun text = uh(fmt::format("explore '{}' --object {}", path.string(), name), cache);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("stiffness  1.500 N/mm"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("(the rendered stiffness: through the proxy the device renders at most 1.500 N/mm "
                          "passively, and the material is stiffer; --proxy off reads the material's)"),
            std::string::npos)
      << text.out;
}

TEST_F(CliTest, MuseumJudgeReportsItsVerdictsAndTheirEvidence) {
  // the artifacts' packings are kept in the build tree (built once, like the test command's other caches)
  const std::string cache = fmt::format("UH_CACHE_DIR='{}' ", UH_TEST_CACHE_DIR);
  const CommandRun r = uh("museum judge --kinds coin --seed 1 --json", cache);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = json_of(r);
  EXPECT_EQ(out["level"], "easy");
  ASSERT_EQ(out["pairs"].size(), 1u);
  const nlohmann::json& pair = out["pairs"][0];
  EXPECT_EQ(pair["kind"], "coin");
  ASSERT_EQ(pair["pieces"].size(), 2u);
  int correct = 0;
  std::set<std::string> truths;
  for (const auto& piece : pair["pieces"]) {
    truths.insert(piece["truth"].get<std::string>());
    EXPECT_EQ(piece["correct"].get<bool>(), piece["truth"] == piece["verdict"]);
    correct += piece["correct"].get<bool>() ? 1 : 0;
    ASSERT_FALSE(piece["evidence"].empty());
    bool any_differs = false;
    for (const auto& f : piece["evidence"]) {
      EXPECT_TRUE(f["unit"] == "mm" || f["unit"] == "%") << f.dump();
      EXPECT_EQ(f["differs"].get<bool>(), f["difference"].get<double>() > f["threshold"].get<double>());
      any_differs = any_differs || f["differs"].get<bool>();
    }
    // a forgery verdict rests on a feature that differs, a genuine one on none
    EXPECT_EQ(any_differs, piece["verdict"] == "forgery");
  }
  EXPECT_EQ(truths, (std::set<std::string>{"genuine", "forgery"}));
  EXPECT_DOUBLE_EQ(out["accuracy"].get<double>(), correct / 2.0);

  const CommandRun bad = uh("museum judge --kinds coin,teapot", cache);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("'teapot' is no artifact kind"), std::string::npos) << bad.err;
}

TEST_F(CliTest, MuseumPlayBotsPlaysARoundToItsSummary) {
  // a three-minute round at 10 times the clock (at most 18 s): the server, the sighted bot and the
  // blind bot as clients over loopback sockets
  const std::string cache = fmt::format("UH_CACHE_DIR='{}' ", UH_TEST_CACHE_DIR);
  const CommandRun r = uh("museum play --bots --seed 1 --minutes 3 --speed 10 --json", cache);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json out = json_of(r);
  const nlohmann::json& summary = out["summary"];
  ASSERT_EQ(summary["type"], "summary");
  EXPECT_GT(summary["seconds_played"].get<double>(), 0.0);
  ASSERT_EQ(summary["targets"].size(), 3u) << "the easy level names three targets";
  // the points are what the pieces' places say
  const nlohmann::json& score = summary["score"];
  EXPECT_EQ(score["points"].get<int>(),
            100 * score["genuine_kept"].get<int>() - 60 * score["forgeries_kept"].get<int>() +
                score["time_bonus"].get<int>());
  // every piece kept or put aside is one the blind bot judged so, from evidence that says so
  int settled = 0;
  for (const auto& t : summary["targets"]) {
    for (const char* piece : {"genuine", "forgery"}) {
      const std::string place = t[piece];
      if (place != "kept" && place != "rejected") continue;
      ++settled;
      bool found = false;
      for (const auto& v : out["verdicts"])
        found = found || (v["kind"] == t["kind"] && (v["verdict"] == "genuine") == (place == "kept"));
      EXPECT_TRUE(found) << t.dump();
    }
  }
  // Vive brought pieces to the table, and Phantom felt the first it was handed (a verdict may come
  // after the end: the round does not wait for Phantom)
  EXPECT_GE(out["events"]["items_delivered"].get<int>(), 1) << out["events"].dump();
  EXPECT_GE(out["verdicts"].size(), std::max<std::size_t>(1, static_cast<std::size_t>(settled)));
  for (const auto& v : out["verdicts"]) {
    bool differs = false;
    for (const auto& f : v["evidence"]) differs = differs || f["differs"].get<bool>();
    EXPECT_EQ(differs, v["verdict"] == "forgery") << v.dump();
    EXPECT_GT(v["simulated_s"].get<double>(), 10.0) << "each piece is explored by touch";
  }

  const CommandRun alone = uh("museum play --seed 2");
  EXPECT_NE(alone.exit_code, 0);
  EXPECT_NE(alone.err.find("give --bots, or --bot vive|phantom with --server URL"), std::string::npos) << alone.err;
  const CommandRun nobody = uh("museum play --bot phantom --server ws://127.0.0.1:1/ws");
  EXPECT_NE(nobody.exit_code, 0);
  EXPECT_NE(nobody.err.find("museum server at ws://127.0.0.1:1/ws: cannot reach the server"),
            std::string::npos)
      << nobody.err;
  const CommandRun nowhere = uh("museum play --bot vive --server ftp://127.0.0.1:7780/");
  EXPECT_NE(nowhere.exit_code, 0);
  EXPECT_NE(nowhere.err.find("--server 'ftp://127.0.0.1:7780/': the address must be"), std::string::npos)
      << nowhere.err;
}

TEST_F(CliTest, ExploreNamesAnUnknownObjectAndWritesItsPlot) {
  const CommandRun bad = uh(fmt::format("explore '{}' --object marble", materials_scene_path().string()),
                            fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("no object is named 'marble'"), std::string::npos) << bad.err;
  const fs::path png = dir_ / "sticky.png";
  const CommandRun r = uh(
      fmt::format("explore '{}' --object sticky --plot '{}'", materials_scene_path().string(), png.string()),
      fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("friction   static"), std::string::npos) << r.out;
  EXPECT_EQ(read_text(png).substr(1, 3), "PNG");
}

// a PNG's height, from its header (IHDR: width, then height, big-endian, from byte 16)
std::uint32_t png_height(const std::string& png) {
  std::uint32_t h = 0;
  for (std::size_t i = 20; i < 24 && i < png.size(); ++i) h = (h << 8) | static_cast<unsigned char>(png[i]);
  return h;
}

// a scene with a soft object gets a fourth panel: its indentation against the force
TEST_F(CliTest, RunPlotsASoftObjectsIndentationAgainstForce) {
  const fs::path soft = dir_ / "soft.png", rigid = dir_ / "rigid.png";
  const fs::path scenes = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes";
  const std::string env = fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string());
  const CommandRun r = uh(fmt::format("run '{}' --stepped --seconds 1 --plot '{}'",
                                      (scenes / "soft_block.json").string(), soft.string()), env);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CommandRun b = uh(fmt::format("run '{}' --stepped --seconds 0.2 --plot '{}'",
                                      (scenes / "bunny_sweep.json").string(), rigid.string()), env);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(png_height(read_text(soft)), 4u * 260u);
  EXPECT_EQ(png_height(read_text(rigid)), 3u * 260u);
}

// A ball tool that begins inside the block has no side to keep: the proxy follows the handle
// freely, the run feels nothing, and the summary says why; started above the block it holds.
TEST_F(CliTest, RunSaysWhenTheToolBeganInsideAnObject) {
  const fs::path scenes = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes";
  std::ifstream in(scenes / "soft_block.json");
  nlohmann::json j = nlohmann::json::parse(in);
  j["objects"][0].erase("deformable");
  j["objects"][0]["mesh"] = (scenes / j["objects"][0]["mesh"].get<std::string>()).lexically_normal().string();
  j["tool"]["mesh"] = (scenes / j["tool"]["mesh"].get<std::string>()).lexically_normal().string();
  const std::string env = fmt::format("UH_CACHE_DIR='{}' ", (dir_ / "cache").string());
  const auto run_from = [&](double start_z) {
    // the ball (1 cm radius) from start_z down to 4 mm below the block's top face (z = 0)
    j["tool"]["device"]["config"]["start"] = {0.0, 0.0, start_z};
    j["tool"]["device"]["config"]["end"] = {0.0, 0.0, -0.004};
    const fs::path scene = dir_ / fmt::format("began_{}.json", static_cast<int>(start_z * 1000));
    std::ofstream(scene) << j.dump(2);
    return uh(fmt::format("run '{}' --stepped --seconds 1", scene.string()), env);
  };
  const CommandRun inside = run_from(0.008);
  ASSERT_EQ(inside.exit_code, 0) << inside.err;
  EXPECT_NE(inside.out.find("the tool began inside an object: the proxy followed the handle freely"), std::string::npos)
      << inside.out;
  EXPECT_NE(inside.out.find(" 0 in contact"), std::string::npos) << inside.out;
  const CommandRun above = run_from(0.012);
  ASSERT_EQ(above.exit_code, 0) << above.err;
  EXPECT_EQ(above.out.find("began inside"), std::string::npos) << above.out;
  EXPECT_EQ(above.out.find(" 0 in contact"), std::string::npos) << above.out;
}

// a threaded run clocked by HD's scheduler (the stand-in's own thread)
TEST_F(CliTest, RunOnOpenHapticsNamedOnTheCommandLine) {
  const fs::path scene = write_small_device_scene(dir_);
  const CommandRun r = uh(fmt::format("run '{}' --device openhaptics --seconds 0.3 --json", scene.string()),
                          with_standin(dir_));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["haptic"]["ticks"].get<int>(), 100);
  EXPECT_GT(j["force"]["max_n"].get<double>(), 0.5);
  EXPECT_LE(j["force"]["max_n"].get<double>(), 3.3);
  EXPECT_EQ(j["device"]["name"], "openhaptics Touch");
  EXPECT_EQ(j["device"]["serial"], "220-00042");
  EXPECT_EQ(j["device"]["com_rate_hz"], 0.0);  // HD reports no communication rate
  const CommandRun named =
      uh(fmt::format("run '{}' --device 'openhaptics:Left Touch' --seconds 0.3", scene.string()),
         with_standin(dir_));
  EXPECT_EQ(named.exit_code, 1);
  EXPECT_NE(named.err.find("openhaptics: opening 'Left Touch' (hdInitDevice) failed: HD error 0x302"),
            std::string::npos)
      << named.err;
}

// Every scene in scenes/ (whatever is added later), two simulated seconds each: it runs, touches
// something, sends only finite forces within its device's limit, and renders on the path it asks
// for: the proxy by default (every step solved, the tool never sunk into a surface, no net energy
// into the hand), the penalty path where it enables the virtual coupling.
TEST_F(CliTest, EveryShippedSceneRunsWithinItsLimitsOnItsPath) {
  const fs::path scenes = fs::path(UH_TEST_DATA_DIR).parent_path() / "scenes";
  std::set<fs::path> files;
  for (const auto& e : fs::directory_iterator(scenes))
    if (e.path().extension() == ".json") files.insert(e.path());
  ASSERT_GE(files.size(), 10u) << scenes;
  const std::string cache = fmt::format("UH_CACHE_DIR='{}' ", UH_TEST_CACHE_DIR);
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    std::ifstream in(file);
    const nlohmann::json scene = nlohmann::json::parse(in);
    const bool coupling = scene.value(nlohmann::json::json_pointer("/force/coupling/enabled"), false);
    const bool proxy = !coupling && scene.value(nlohmann::json::json_pointer("/force/proxy/enabled"), true);
    const CommandRun r = uh(fmt::format("run '{}' --stepped --seconds 2 --json", file.string()), cache);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json out = json_of(r);
    const nlohmann::json& force = out["force"];
    EXPECT_GT(out["contact"]["ticks"].get<int>(), 0) << "every shipped scene is about touching something";
    EXPECT_EQ(force["nonfinite"].get<int>(), 0);
    EXPECT_LE(force["max_n"].get<double>(), out["device"]["max_force_n"].get<double>() + 1e-9);
    ASSERT_EQ(force.value("proxy", nlohmann::json{}).is_object(), proxy) << "rendered on the path the scene asks for";
    if (!proxy) continue;
    EXPECT_GT(force["proxy"]["contact_updates"].get<int>(), 0);
    EXPECT_EQ(force["proxy"]["unsolved"].get<int>(), 0);
    EXPECT_LT(force["proxy"]["deepest_m"].get<double>(), 0.5e-3) << "the tool stays on the surface";
    EXPECT_LE(out["energy"]["work_on_hand_j"].get<double>(), 1e-3) << "the proxy puts no net energy in";
  }
}

}  // namespace
}  // namespace uh
