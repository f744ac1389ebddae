// The one reader of JSON fields: the nesting guard before parsing, and errors that name the field's path.

#include "uh/core/json_fields.hpp"

#include <gtest/gtest.h>

#include <string>

namespace uh {
namespace {

using nlohmann::json;

TEST(JsonFields, TheGuardRefusesDeepNestingBeforeParsing) {
  EXPECT_TRUE(parse_json_document(R"({"a": [1, {"b": 2}]})"));
  const auto deep = parse_json_document(std::string(100000, '[') + std::string(100000, ']'));
  ASSERT_FALSE(deep);
  EXPECT_EQ(deep.error().message, "the JSON is nested deeper than 32 levels");
  const auto bad = parse_json_document("{nope");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message.rfind("not valid JSON: [json.exception.parse_error", 0), 0u) << bad.error().message;
  // a number no double holds is the text's fault too
  EXPECT_FALSE(parse_json_document(R"({"x": 1e999})"));
}

TEST(JsonFields, ReadsTypedFieldsAndNamesTheFirstOneWrong) {
  const json m =
      json::parse(R"({"n": 1.5, "i": 7, "b": true, "t": "x", "a": [1, "two"], "o": {"deep": "no"}})");
  JsonFields f;
  EXPECT_EQ(f.number(m, "n"), 1.5);
  EXPECT_EQ(f.integer(m, "i"), 7);
  EXPECT_TRUE(f.boolean(m, "b"));
  EXPECT_EQ(f.text(m, "t"), "x");
  const json* a = f.array(m, "a");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(f.integer_of((*a)[0], "a[0]"), 1);
  EXPECT_EQ(f.optional(m, "missing"), nullptr);
  EXPECT_TRUE(f.ok());
  EXPECT_EQ(f.integer_of((*a)[1], "a[1]"), 0);
  EXPECT_EQ(f.error(), "'a[1]' must be an integer");
  // the first error stays; later reads do nothing
  EXPECT_EQ(f.number(m, "t"), 0.0);
  EXPECT_EQ(f.error(), "'a[1]' must be an integer");

  const struct {
    const char* field;
    const char* says;
  } cases[] = {{"missing", "'o.missing' is missing"}, {"deep", "'o.deep' must be a finite number"}};
  for (const auto& c : cases) {
    JsonFields g;
    g.number(m["o"], c.field, "o.");
    EXPECT_EQ(g.error(), c.says);
  }
  JsonFields h;
  h.integer(json::parse(R"({"big": 18446744073709551615})"), "big");
  EXPECT_EQ(h.error(), "'big' must be an integer");
  JsonFields k;
  k.text(m["a"], "x", "a.");
  EXPECT_EQ(k.error(), "'a' must be an object");
}

}  // namespace
}  // namespace uh
