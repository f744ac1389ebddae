// The service's message parser and scene editing, without sockets: every documented request
// parses, and every bad one gets an error that names what is wrong (docs/protocol.md).

#include "protocol.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "mesh_binary.hpp"
#include "scene_document.hpp"
#include "service_test_support.hpp"
#include "uh/collette/mesh_import.hpp"

namespace uh::service {
namespace {

ParsedRequest parse(const std::string& text) { return parse_request(text); }

TEST(Protocol, ParsesEveryRequestType) {
  const char* messages[] = {
      R"({"type":"hello","protocol":1,"token":"t"})",
      R"({"type":"open"})",
      R"({"type":"open","scene":"a.json"})",
      R"({"type":"start","seconds":2})",
      R"({"type":"stop"})",
      R"({"type":"ping"})",
      R"({"type":"close"})",
      R"({"type":"subscribe","rate_hz":30})",
      R"({"type":"unsubscribe"})",
      R"({"type":"get_scene"})",
      R"({"type":"get_mesh","object":"bunny"})",
      R"({"type":"add_object","object":{"name":"b"}})",
      R"({"type":"remove_object","name":"b"})",
      R"({"type":"set_pose","object":"b","pose":{}})",
      R"({"type":"set_watch","objects":["b"]})",
      R"({"type":"set_device","device":{"driver":"sim-line"}})",
      R"({"type":"set_tool","tool":{"force":{"damping":3}}})",
      R"({"type":"set_rates","haptic_hz":2000})",
  };
  for (const char* m : messages) {
    const ParsedRequest r = parse(m);
    EXPECT_TRUE(r.body.has_value()) << m << ": " << r.error;
  }
  const ParsedRequest sub = parse(R"({"type":"subscribe"})");
  ASSERT_TRUE(sub.body);
  EXPECT_EQ(std::get<Subscribe>(*sub.body).rate_hz, kDefaultStateRateHz);
  const ParsedRequest open = parse(R"({"type":"open"})");
  EXPECT_FALSE(std::get<Open>(*open.body).scene.has_value()) << "no scene: the default";
}

TEST(Protocol, KeepsTheIdOfGoodAndBadRequests) {
  EXPECT_EQ(parse(R"({"type":"ping","id":42})").id, 42);
  EXPECT_EQ(parse(R"({"type":"ping","id":"x"})").id, "x");
  const ParsedRequest bad = parse(R"({"type":"nonsense","id":7})");
  EXPECT_FALSE(bad.body);
  EXPECT_EQ(bad.id, 7);
  EXPECT_EQ(bad.type, "nonsense");
  const ParsedRequest bad_id = parse(R"({"type":"ping","id":[1]})");
  EXPECT_FALSE(bad_id.body);
  EXPECT_NE(bad_id.error.find("'id'"), std::string::npos) << bad_id.error;
}

TEST(Protocol, ErrorsNameWhatIsWrong) {
  struct Case {
    const char* text;
    const char* expected;  // a part of the error
  };
  const Case cases[] = {
      {R"({"type":"hello","protocol":1)", "not valid JSON"},
      {"", "not valid JSON"},
      {R"([1,2])", "expected a JSON object, got array"},
      {R"({"protocol":1})", "field 'type' is missing"},
      {R"({"type":5})", "field 'type': expected a string, got number"},
      {R"({"type":"helo","protocol":1})", "unknown message type 'helo'"},
      {R"({"type":"set_rates"})", "needs 'haptic_hz' or 'collision_hz'"},
      {R"({"type":"set_tool","tool":"stylus"})", "field 'tool': expected an object, got string"},
      {R"({"type":"hello"})", "field 'protocol' is missing"},
      {R"({"type":"hello","protocol":"1"})", "field 'protocol': expected a whole number, got string"},
      {R"({"type":"open","scene":3})", "field 'scene': expected a non-empty string, got number"},
      {R"({"type":"open","scenes":"a"})", "unknown field 'scenes'"},
      {R"({"type":"start","seconds":-1})", "field 'seconds': expected a number in"},
      {R"({"type":"subscribe","rate_hz":"fast"})", "field 'rate_hz': expected a number, got string"},
      {R"({"type":"subscribe","rate_hz":5000})", "field 'rate_hz': expected a number in [1, 1000], got 5000"},
      {R"({"type":"get_mesh"})", "field 'object' is missing"},
      {R"({"type":"add_object","object":[1]})", "field 'object': expected an object, got array"},
      {R"({"type":"set_watch","objects":[1]})", "field 'objects[0]': expected an object name, got number"},
      {R"({"type":"stop","now":true})", "unknown field 'now' (known here: none)"},
      {R"({"type":"ping","x":1e999})", "not valid JSON"},
  };
  for (const Case& c : cases) {
    const ParsedRequest r = parse(c.text);
    EXPECT_FALSE(r.body.has_value()) << c.text;
    EXPECT_NE(r.error.find(c.expected), std::string::npos) << c.text << " -> " << r.error;
  }
}

TEST(Protocol, RefusesDeepNestingBeforeParsing) {
  const std::string deep =
      R"({"type":"ping","x":)" + std::string(100000, '[') + std::string(100000, ']') + "}";
  const ParsedRequest r = parse(deep);
  EXPECT_FALSE(r.body);
  EXPECT_NE(r.error.find("nested deeper than"), std::string::npos) << r.error;
  // brackets inside strings do not count
  EXPECT_TRUE(parse(R"({"type":"get_mesh","object":")" + std::string(100, '[') + "\"}").body);
}

TEST(Protocol, RepliesEchoTheIdAndAreJson) {
  const json r = json::parse(reply("pong", 3, {{"time_s", 1.5}}));
  EXPECT_EQ(r["type"], "pong");
  EXPECT_EQ(r["id"], 3);
  EXPECT_EQ(r["time_s"], 1.5);
  EXPECT_FALSE(json::parse(reply("closed", nullptr)).contains("id"));
  const json e = json::parse(error_reply("a", "open", "scene.json: cannot open the scene file"));
  EXPECT_EQ(e["type"], "error");
  EXPECT_EQ(e["id"], "a");
  EXPECT_EQ(e["request"], "open");
  EXPECT_EQ(e["message"], "scene.json: cannot open the scene file");
  // text that is not UTF-8 (a file name, say) is replaced, not a crash
  EXPECT_NO_THROW(json::parse(error_reply(nullptr, "", std::string("bad \xff name"))));
}

class SceneDocumentTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::scratch("document");
    auto d = SceneDocument::open_file(testing::write_small_scene(dir_));
    ASSERT_TRUE(d.has_value()) << d.error().message;
    doc_.emplace(std::move(d).value());
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
  std::optional<SceneDocument> doc_;
};

TEST_F(SceneDocumentTest, EditsGoThroughTheSceneParser) {
  const auto assets = testing::assets();
  // paths in edits are relative to the given folder (the service's working folder)
  ASSERT_TRUE(doc_->add_object({{"name", "bunny2"},
                                {"mesh", "meshes/bunny_npm_3674.obj"},
                                {"spheres", 300},
                                {"meters_per_unit", 0.01},
                                {"pose", {{"position", {0.2, 0, 0}}}}},
                               assets));
  ASSERT_EQ(doc_->scene().objects.size(), 2u);
  EXPECT_EQ(doc_->scene().objects[1].shape.mesh, assets / "meshes" / "bunny_npm_3674.obj");
  EXPECT_EQ(doc_->scene().objects[1].pose.position.x, 0.2);
  EXPECT_EQ(doc_->scene().watch.size(), 2u) << "a scene without a watch list watches every object";

  ASSERT_TRUE(doc_->set_pose("bunny2", {{"position", {0.3, 0.1, 0}}, {"rotation", {0, 0, 0, 2}}}));
  EXPECT_EQ(doc_->scene().objects[1].pose.position.y, 0.1);
  EXPECT_EQ(doc_->scene().objects[1].pose.rotation.z, 1.0) << "normalised by the parser";

  ASSERT_TRUE(doc_->set_watch({"bunny2"}));
  EXPECT_EQ(doc_->scene().watch, std::vector<std::string>{"bunny2"});
  ASSERT_TRUE(doc_->remove_object("bunny2"));
  EXPECT_EQ(doc_->scene().objects.size(), 1u);
  EXPECT_TRUE(doc_->scene().watch.empty()) << "removed from the watch list too";

  ASSERT_TRUE(doc_->set_device({{"driver", "sim-circle"}, {"config", {{"radius", 0.03}}}}, assets));
  EXPECT_EQ(doc_->scene().tool().device.driver, "sim-circle");

  // set_tool merges: the damping changes, the stiffness and the device stay
  const double stiffness = doc_->scene().tool().force.stiffness;
  ASSERT_TRUE(doc_->set_tool({{"force", {{"damping", 3.5}}}}, assets));
  EXPECT_EQ(doc_->scene().tool().force.damping, 3.5);
  EXPECT_EQ(doc_->scene().tool().force.stiffness, stiffness);
  EXPECT_EQ(doc_->scene().tool().device.driver, "sim-circle");
  ASSERT_TRUE(doc_->set_tool({{"mesh", "meshes/stylus.obj"}, {"spheres", 50}}, assets));
  EXPECT_EQ(doc_->scene().tool().shape.mesh, assets / "meshes" / "stylus.obj");
  EXPECT_FALSE(doc_->set_tool({{"force", {{"damping", "much"}}}}, assets).has_value());
  EXPECT_EQ(doc_->scene().tool().force.damping, 3.5) << "a refused patch changes nothing";

  ASSERT_TRUE(doc_->set_rates(2000.0, std::nullopt));
  EXPECT_EQ(doc_->scene().haptic_hz, 2000.0);
  EXPECT_EQ(doc_->scene().collision_hz, 500.0) << "the rate not given stays";
  const Status too_fast = doc_->set_rates(std::nullopt, -3.0);
  ASSERT_FALSE(too_fast.has_value());
  EXPECT_NE(too_fast.error().message.find("rates.collision_hz"), std::string::npos)
      << too_fast.error().message;
}

TEST_F(SceneDocumentTest, RefusedEditsLeaveTheSceneAsItWas) {
  const auto fails_with = [](const Status& s, const std::string& part) {
    ASSERT_FALSE(s.has_value());
    EXPECT_NE(s.error().message.find(part), std::string::npos) << s.error().message;
  };
  fails_with(doc_->add_object({{"name", "x"}, {"mesh", "no_such.obj"}}, dir_), "file not found");
  fails_with(doc_->add_object(
                 {{"name", "bunny"}, {"mesh", (testing::assets() / "meshes" / "stylus.obj").string()}}, dir_),
             "duplicate object name 'bunny'");
  fails_with(doc_->add_object({{"name", "x"}, {"mesh", "a.obj"}, {"colour", "red"}}, dir_), "unknown field");
  fails_with(doc_->set_pose("nobody", {{"position", {0, 0, 0}}}), "no object is named 'nobody'");
  fails_with(doc_->set_pose("bunny", {{"position", {0, 0}}}), "objects[0].pose.position");
  fails_with(doc_->set_watch({"nobody"}), "no object is named 'nobody'");
  fails_with(doc_->remove_object("bunny"), "the last object");
  fails_with(doc_->set_device({{"config", {{"radius", 0.03}}}}, dir_), "tool.device.driver");
  EXPECT_EQ(doc_->scene().objects.size(), 1u);
  EXPECT_EQ(doc_->scene().objects[0].pose.position.x, 0.0);
  EXPECT_EQ(doc_->scene().tool().device.driver, "sim-line");
}

TEST_F(SceneDocumentTest, MeshesAreInMetresInTheObjectFrame) {
  auto mesh = scene_mesh(doc_->scene(), "stylus");
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  const auto& v = (*mesh)["vertices"];
  const auto& t = (*mesh)["triangles"];
  ASSERT_GT(v.size(), 0u);
  EXPECT_EQ(v.size() % 3, 0u);
  EXPECT_EQ(t.size() % 3, 0u);
  double top = 0.0;
  for (std::size_t i = 2; i < v.size(); i += 3) top = std::max(top, v[i].get<double>());
  EXPECT_NEAR(top, 0.05, 1e-9) << "the stylus is 5 units long, 0.01 m each";
  for (const auto& i : t) EXPECT_LT(i.get<std::size_t>(), v.size() / 3);
  EXPECT_FALSE(scene_mesh(doc_->scene(), "nobody").has_value());
  const json description = describe_scene(doc_->scene());
  EXPECT_EQ(description["objects"][0]["name"], "bunny");
  EXPECT_EQ(description["tool"]["device"], "sim-line");
}

TEST(Protocol, AddObjectAnnouncesAnInlineMesh) {
  const ParsedRequest ok = parse(
      R"({"type":"add_object","id":3,"object":{"name":"b"},"mesh_binary":{"vertices":5,"triangles":6}})");
  ASSERT_TRUE(ok.body) << ok.error;
  EXPECT_TRUE(ok.announces_binary);
  const auto& counts = *std::get<AddObject>(*ok.body).mesh_binary;
  EXPECT_EQ(counts.vertices, 5);
  EXPECT_EQ(counts.bytes(), 12u * 11u);
  EXPECT_FALSE(parse(R"({"type":"add_object","object":{"name":"b","mesh":"b.obj"}})").announces_binary);

  struct Case {
    const char* text;
    const char* part;
  };
  const Case cases[] = {
      {R"({"type":"add_object","object":{"name":"b"},"mesh_binary":[5,6]})",
       "field 'mesh_binary': expected an object"},
      {R"({"type":"add_object","object":{"name":"b"},"mesh_binary":{"vertices":5}})",
       "'mesh_binary.triangles' is missing"},
      {R"({"type":"add_object","object":{"name":"b"},"mesh_binary":{"vertices":5.5,"triangles":6}})",
       "'mesh_binary.vertices': expected a whole number, got number"},
      {R"({"type":"add_object","object":{"name":"b"},"mesh_binary":{"vertices":3,"triangles":6}})",
       "'mesh_binary.vertices': expected a whole number in [4, "},
      {R"({"type":"add_object","object":{"name":"b"},"mesh_binary":{"vertices":5,"triangles":6,"normals":1}})",
       "unknown field 'mesh_binary.normals'"},
      {R"({"type":"add_object","object":{"name":"b"},"mesh_binary":{"vertices":4000000,"triangles":4000000}})",
       "above the limit of 67108864 bytes"},
      {R"({"type":"add_object","object":{"name":"b","mesh":"b.obj"},"mesh_binary":{"vertices":5,"triangles":6}})",
       "field 'object.mesh': not allowed with 'mesh_binary'"},
  };
  for (const Case& c : cases) {
    const ParsedRequest r = parse(c.text);
    EXPECT_FALSE(r.body) << c.text;
    EXPECT_TRUE(r.announces_binary) << "a refused announcement still owns its frame: " << c.text;
    EXPECT_NE(r.error.find(c.part), std::string::npos) << c.text << " -> " << r.error;
  }
}

// The frame written by hand, byte by byte, as a client on a little-endian machine sends it
// (memcpy of float and uint32): the reference for the decoder's and encoder's byte shuffling.
std::string frame_by_hand(const std::vector<float>& coordinates, const std::vector<std::uint32_t>& indices) {
  static_assert(std::endian::native == std::endian::little, "the reference assumes a little-endian host");
  std::string out(4 * (coordinates.size() + indices.size()), '\0');
  std::memcpy(out.data(), coordinates.data(), 4 * coordinates.size());
  std::memcpy(out.data() + 4 * coordinates.size(), indices.data(), 4 * indices.size());
  return out;
}

std::span<const std::byte> bytes_of(const std::string& s) {
  return std::as_bytes(std::span(s.data(), s.size()));
}

const std::vector<float> kTetrahedron = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1.5f};
const std::vector<std::uint32_t> kTetrahedronFaces = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};

TEST(MeshBinary, DecodesTheFrameAsSentAndEncodesItBack) {
  const std::string frame = frame_by_hand(kTetrahedron, kTetrahedronFaces);
  auto mesh = decode_mesh_binary(bytes_of(frame), MeshBinary{4, 4}, "add_object 't'");
  ASSERT_TRUE(mesh.has_value()) << mesh.error().message;
  ASSERT_EQ(mesh->vertices.size(), 4u);
  EXPECT_EQ(mesh->vertices[3].z, 1.5);
  EXPECT_EQ(mesh->triangles[3], (std::array<std::int32_t, 3>{1, 2, 3}));
  EXPECT_EQ(mesh->source_name, "add_object 't' (mesh_binary)");
  EXPECT_EQ(encode_mesh_binary(*mesh), frame);
}

TEST(MeshBinary, RefusesFramesThatDoNotMatchTheirAnnouncement) {
  const auto fails_with = [](const std::string& frame, MeshBinary counts, const std::string& part) {
    auto mesh = decode_mesh_binary(bytes_of(frame), counts, "add_object 't'");
    ASSERT_FALSE(mesh.has_value()) << part;
    EXPECT_NE(mesh.error().message.find(part), std::string::npos) << mesh.error().message;
    EXPECT_EQ(mesh.error().message.rfind("add_object 't': ", 0), 0u) << "names the request";
  };
  const std::string good = frame_by_hand(kTetrahedron, kTetrahedronFaces);
  fails_with(good.substr(0, good.size() - 1), {4, 4}, "the binary frame has 95 bytes");
  fails_with(good + "xxxx", {4, 4}, "12 * (4 + 4) = 96 bytes");
  fails_with(good, {5, 4}, "12 * (5 + 4) = 108 bytes");
  auto nan = kTetrahedron;
  nan[4] = std::numeric_limits<float>::quiet_NaN();
  fails_with(frame_by_hand(nan, kTetrahedronFaces), {4, 4}, "vertex 1 is not finite");
  auto inf = kTetrahedron;
  inf[11] = -std::numeric_limits<float>::infinity();
  fails_with(frame_by_hand(inf, kTetrahedronFaces), {4, 4}, "vertex 3 is not finite");
  auto far = kTetrahedronFaces;
  far[7] = 4;
  fails_with(frame_by_hand(kTetrahedron, far), {4, 4},
             "triangle 2 uses vertex 4, but there are only 4 vertices");
  far[7] = 0xffffffffu;  // not read as -1
  fails_with(frame_by_hand(kTetrahedron, far), {4, 4}, "uses vertex 4294967295");
}

TEST_F(SceneDocumentTest, AnInlineMeshIsCheckedLikeAFileAndStoredByContent) {
  auto bunny = collette::load_mesh(testing::assets() / "meshes" / "bunny_npm_3674.obj");
  ASSERT_TRUE(bunny.has_value()) << bunny.error().message;
  const json object = {{"name", "inline"}, {"spheres", 200}, {"meters_per_unit", 0.01}};
  const auto mesh_dir = dir_ / "inline-meshes";
  // as the service does it: the mesh checked and written (off its network thread), then added
  const auto add_inline_object = [&](const json& o,
                                     const collette::TriangleMesh& mesh) -> Result<collette::MeshReport> {
    auto written = write_inline_mesh(mesh, mesh_dir);
    if (!written) return written.error();
    if (auto added = doc_->add_inline_object(o, written->file); !added) return added.error();
    return written->report;
  };
  // sent with the opposite winding, as an engine with clockwise front faces would: fixed as for files
  collette::TriangleMesh flipped = *bunny;
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  auto report = add_inline_object(object, flipped);
  ASSERT_TRUE(report.has_value()) << report.error().message;
  EXPECT_TRUE(report->winding_flipped);
  EXPECT_EQ(report->vertex_count, static_cast<std::int64_t>(bunny->vertices.size()));
  const std::filesystem::path stored_path = doc_->scene().objects.back().shape.mesh;
  EXPECT_EQ(stored_path.parent_path(), mesh_dir);
  // the stored file reads back as the same closed mesh
  auto stored = collette::load_mesh(stored_path);
  ASSERT_TRUE(stored.has_value()) << stored.error().message;
  EXPECT_EQ(stored->triangles.size(), bunny->triangles.size());
  EXPECT_NEAR(stored->report.volume, bunny->report.volume, 1e-9 * bunny->report.volume);
  // the same mesh again is the same file (the packing cache is keyed by the file's content)
  ASSERT_TRUE(add_inline_object({{"name", "again"}, {"spheres", 200}}, flipped));
  EXPECT_EQ(doc_->scene().objects.back().shape.mesh, stored_path);

  // an open mesh is refused naming the request, as a file is naming the file
  collette::TriangleMesh open = *bunny;
  open.source_name = "add_object 'open' (mesh_binary)";
  open.triangles.pop_back();
  auto refused = add_inline_object({{"name", "open"}}, open);
  ASSERT_FALSE(refused.has_value());
  EXPECT_NE(refused.error().message.find("add_object 'open' (mesh_binary): mesh is not closed"),
            std::string::npos)
      << refused.error().message;
  // a refused object (its name is taken) changes nothing
  EXPECT_FALSE(add_inline_object({{"name", "bunny"}}, *bunny).has_value());
  EXPECT_EQ(doc_->scene().objects.size(), 3u);
}

TEST(SceneDocument, MissingSceneFileIsNamed) {
  auto d = SceneDocument::open_file("/nonexistent/scene.json");
  ASSERT_FALSE(d.has_value());
  EXPECT_EQ(d.error().message, "/nonexistent/scene.json: cannot open the scene file");
}

}  // namespace
}  // namespace uh::service
