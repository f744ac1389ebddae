#include "protocol.hpp"

#include <cmath>
#include <initializer_list>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "uh/core/json_fields.hpp"

namespace uh::service {
namespace {

// Reads the fields of one request object; every error names the field.
class Fields {
 public:
  explicit Fields(const json& j) : j_(j) {}

  std::string check_known(std::initializer_list<std::string_view> known) const {
    for (const auto& [key, value] : j_.items()) {
      if (key == "type" || key == "id") continue;
      bool ok = false;
      for (std::string_view k : known) ok = ok || key == k;
      if (!ok) {
        std::string list;
        for (std::string_view k : known) list += fmt::format("{}{}", list.empty() ? "" : ", ", k);
        return fmt::format("unknown field '{}' (known here: {})", key, list.empty() ? "none" : list);
      }
    }
    return {};
  }

  const json* find(std::string_view key) const {
    const auto it = j_.find(std::string(key));
    return it == j_.end() ? nullptr : &*it;
  }

  std::string string(std::string_view key, std::string& out, bool required) const {
    const json* v = find(key);
    if (v == nullptr) return required ? fmt::format("field '{}' is missing (expected a string)", key) : "";
    if (!v->is_string() || v->get_ref<const std::string&>().empty())
      return fmt::format("field '{}': expected a non-empty string, got {}", key, v->type_name());
    out = v->get<std::string>();
    return {};
  }

  std::string number(std::string_view key, double& out, double min, double max) const {
    const json* v = find(key);
    if (v == nullptr) return {};
    if (!v->is_number()) return fmt::format("field '{}': expected a number, got {}", key, v->type_name());
    const double d = v->get<double>();
    if (!std::isfinite(d) || d < min || d > max)
      return fmt::format("field '{}': expected a number in [{}, {}], got {}", key, min, max, d);
    out = d;
    return {};
  }

  std::string object(std::string_view key, json& out) const {
    const json* v = find(key);
    if (v == nullptr) return fmt::format("field '{}' is missing (expected an object)", key);
    if (!v->is_object()) return fmt::format("field '{}': expected an object, got {}", key, v->type_name());
    out = *v;
    return {};
  }

 private:
  const json& j_;
};

// `add_object.mesh_binary`: {"vertices": V, "triangles": T}, the counts of the binary frame that
// follows; the object then takes its mesh from that frame and names no file.
std::string parse_mesh_binary(const Fields& f, AddObject& a) {
  const json& m = *f.find("mesh_binary");
  if (!m.is_object())
    return fmt::format(
        "field 'mesh_binary': expected an object {{\"vertices\": V, \"triangles\": T}}, got {}",
        m.type_name());
  for (const auto& [key, value] : m.items())
    if (key != "vertices" && key != "triangles")
      return fmt::format("unknown field 'mesh_binary.{}' (known here: vertices, triangles)", key);
  MeshBinary counts;
  const std::int64_t max_count = static_cast<std::int64_t>(kMaxMeshBinaryBytes / 12);
  for (const auto& [key, out] : {std::pair<const char*, std::int64_t*>{"vertices", &counts.vertices},
                                 std::pair<const char*, std::int64_t*>{"triangles", &counts.triangles}}) {
    const auto it = m.find(key);
    if (it == m.end()) return fmt::format("field 'mesh_binary.{}' is missing (expected a whole number)", key);
    if (!it->is_number_integer())
      return fmt::format("field 'mesh_binary.{}': expected a whole number, got {}", key, it->type_name());
    const auto n = it->get<std::int64_t>();
    // a closed mesh has at least a tetrahedron's 4 vertices and 4 triangles
    if (n < 4 || n > max_count)
      return fmt::format("field 'mesh_binary.{}': expected a whole number in [4, {}], got {}", key, max_count,
                         n);
    *out = n;
  }
  if (counts.bytes() > kMaxMeshBinaryBytes)
    return fmt::format(
        "field 'mesh_binary': {} vertices and {} triangles make a frame of {} bytes, above the "
        "limit of {} bytes",
        counts.vertices, counts.triangles, counts.bytes(), kMaxMeshBinaryBytes);
  for (const char* key : {"mesh", "ist"})
    if (a.object.contains(key))
      return fmt::format(
          "field 'object.{}': not allowed with 'mesh_binary' (the mesh comes in the binary frame)", key);
  a.mesh_binary = counts;
  return {};
}

// One parser per request type: an error text, or `body` filled.
using BodyParser = std::string (*)(const Fields& f, std::optional<RequestBody>& body);

std::string parse_hello(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"protocol", "token"}); !e.empty()) return e;
  const json* p = f.find("protocol");
  if (p == nullptr) return "field 'protocol' is missing (expected the protocol version, 1)";
  if (!p->is_number_integer()) return fmt::format("field 'protocol': expected a whole number, got {}", p->type_name());
  Hello h;
  const auto v = p->get<std::int64_t>();
  h.protocol = v < 0 || v > 1'000'000 ? -1 : static_cast<int>(v);
  if (auto e = f.string("token", h.token, false); !e.empty()) return e;
  body = h;
  return {};
}

std::string parse_open(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"scene"}); !e.empty()) return e;
  Open o;
  std::string scene;
  if (auto e = f.string("scene", scene, false); !e.empty()) return e;
  if (!scene.empty()) o.scene = scene;
  body = o;
  return {};
}

std::string parse_start(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"seconds"}); !e.empty()) return e;
  Start s;
  double seconds = -1.0;
  if (auto e = f.number("seconds", seconds, 1e-3, 86400.0); !e.empty()) return e;
  if (seconds > 0.0) s.seconds = seconds;
  body = s;
  return {};
}

// a request without fields
template <typename Message>
std::string parse_bare(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({}); !e.empty()) return e;
  body = Message{};
  return {};
}

std::string parse_subscribe(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"rate_hz"}); !e.empty()) return e;
  Subscribe s;
  if (auto e = f.number("rate_hz", s.rate_hz, kMinStateRateHz, kMaxStateRateHz); !e.empty()) return e;
  body = s;
  return {};
}

std::string parse_get_mesh(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"object"}); !e.empty()) return e;
  GetMesh g;
  if (auto e = f.string("object", g.object, true); !e.empty()) return e;
  body = g;
  return {};
}

std::string parse_add_object(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"object", "mesh_binary"}); !e.empty()) return e;
  AddObject a;
  if (auto e = f.object("object", a.object); !e.empty()) return e;
  if (f.find("mesh_binary") != nullptr)
    if (auto e = parse_mesh_binary(f, a); !e.empty()) return e;
  body = a;
  return {};
}

std::string parse_remove_object(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"name"}); !e.empty()) return e;
  RemoveObject r;
  if (auto e = f.string("name", r.name, true); !e.empty()) return e;
  body = r;
  return {};
}

std::string parse_set_pose(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"object", "pose"}); !e.empty()) return e;
  SetPose s;
  if (auto e = f.string("object", s.object, true); !e.empty()) return e;
  if (auto e = f.object("pose", s.pose); !e.empty()) return e;
  body = s;
  return {};
}

std::string parse_set_watch(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"objects"}); !e.empty()) return e;
  const json* list = f.find("objects");
  if (list == nullptr || !list->is_array()) return "field 'objects': expected a list of object names";
  SetWatch s;
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& name = (*list)[i];
    if (!name.is_string() || name.get_ref<const std::string&>().empty())
      return fmt::format("field 'objects[{}]': expected an object name, got {}", i, name.type_name());
    s.objects.push_back(name.get<std::string>());
  }
  body = s;
  return {};
}

std::string parse_set_device(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"device"}); !e.empty()) return e;
  SetDevice s;
  if (auto e = f.object("device", s.device); !e.empty()) return e;
  body = s;
  return {};
}

std::string parse_set_tool(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"tool"}); !e.empty()) return e;
  SetTool s;
  if (auto e = f.object("tool", s.tool); !e.empty()) return e;
  body = s;
  return {};
}

std::string parse_set_rates(const Fields& f, std::optional<RequestBody>& body) {
  if (auto e = f.check_known({"haptic_hz", "collision_hz"}); !e.empty()) return e;
  SetRates s;
  // the scene's validate() checks the ranges and names the scene field
  double hz = -1.0;
  if (auto e = f.number("haptic_hz", hz, 0.0, 1e9); !e.empty()) return e;
  if (hz >= 0.0) s.haptic_hz = hz;
  hz = -1.0;
  if (auto e = f.number("collision_hz", hz, 0.0, 1e9); !e.empty()) return e;
  if (hz >= 0.0) s.collision_hz = hz;
  if (!s.haptic_hz && !s.collision_hz) return "set_rates needs 'haptic_hz' or 'collision_hz'";
  body = s;
  return {};
}

// every request type and its parser, in the order an unknown type's error lists them
constexpr std::pair<std::string_view, BodyParser> kBodyParsers[] = {
    {"hello", parse_hello},
    {"open", parse_open},
    {"start", parse_start},
    {"stop", parse_bare<Stop>},
    {"ping", parse_bare<Ping>},
    {"close", parse_bare<Close>},
    {"subscribe", parse_subscribe},
    {"unsubscribe", parse_bare<Unsubscribe>},
    {"get_scene", parse_bare<GetScene>},
    {"get_mesh", parse_get_mesh},
    {"add_object", parse_add_object},
    {"remove_object", parse_remove_object},
    {"set_pose", parse_set_pose},
    {"set_watch", parse_set_watch},
    {"set_device", parse_set_device},
    {"set_tool", parse_set_tool},
    {"set_rates", parse_set_rates},
};

// Parses the body of a request of `type`; returns an error text or fills `body`.
std::string parse_body(const std::string& type, const Fields& f, std::optional<RequestBody>& body) {
  for (const auto& [name, parser] : kBodyParsers)
    if (type == name) return parser(f, body);
  std::string known;
  for (const auto& entry : kBodyParsers) known += fmt::format("{}{}", known.empty() ? "" : ", ", entry.first);
  return fmt::format("unknown message type '{}' (known: {})", type, known);
}

std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

}  // namespace

ParsedRequest parse_request(std::string_view text) {
  ParsedRequest out;
  auto document = parse_json_document(text);
  if (!document) {
    out.error = document.error().message;
    return out;
  }
  const json& j = *document;
  if (!j.is_object()) {
    out.error = fmt::format("expected a JSON object, got {}", j.type_name());
    return out;
  }
  std::string id_error;
  if (const auto it = j.find("id"); it != j.end()) {
    if (it->is_number_integer() || it->is_string())
      out.id = *it;
    else
      id_error = fmt::format("field 'id': expected a whole number or a string, got {}", it->type_name());
  }
  const auto type = j.find("type");
  if (type == j.end()) {
    out.error = "field 'type' is missing (expected the message type, e.g. \"hello\")";
    return out;
  }
  if (!type->is_string()) {
    out.error = fmt::format("field 'type': expected a string, got {}", type->type_name());
    return out;
  }
  out.type = type->get<std::string>();
  out.announces_binary = out.type == "add_object" && j.contains("mesh_binary");
  if (!id_error.empty()) {
    out.error = id_error;
    return out;
  }
  out.error = parse_body(out.type, Fields(j), out.body);
  return out;
}

json deformed_json(std::string_view object, std::uint64_t step, std::span<const float> xyz) {
  json vertices = json::array();
  auto& array = vertices.get_ref<json::array_t&>();
  array.reserve(xyz.size());
  for (const float v : xyz) array.emplace_back(static_cast<std::int64_t>(std::lround(static_cast<double>(v) / kDeformedUnitM)));
  return {{"object", std::string(object)}, {"step", step}, {"unit_m", kDeformedUnitM}, {"vertices", std::move(vertices)}};
}

std::string reply(std::string_view type, const json& id, json fields) {
  json out = json::object();
  out["type"] = std::string(type);
  if (!id.is_null()) out["id"] = id;
  for (auto& [key, value] : fields.items()) out[key] = std::move(value);
  return dump(out);
}

std::string error_reply(const json& id, std::string_view request_type, std::string_view message) {
  json fields = {{"message", std::string(message)}};
  if (!request_type.empty()) fields["request"] = std::string(request_type);
  return reply("error", id, std::move(fields));
}

}  // namespace uh::service
