// The service's message parser and scene editing, without sockets: every documented request
// parses, and every bad one gets an error that names what is wrong (docs/protocol.md).

#include "protocol.hpp"

#include <gtest/gtest.h>

#include "scene_document.hpp"
#include "service_test_support.hpp"

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
  EXPECT_EQ(doc_->scene().tool.device.driver, "sim-circle");
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
  EXPECT_EQ(doc_->scene().tool.device.driver, "sim-line");
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

TEST(SceneDocument, MissingSceneFileIsNamed) {
  auto d = SceneDocument::open_file("/nonexistent/scene.json");
  ASSERT_FALSE(d.has_value());
  EXPECT_EQ(d.error().message, "/nonexistent/scene.json: cannot open the scene file");
}

}  // namespace
}  // namespace uh::service
