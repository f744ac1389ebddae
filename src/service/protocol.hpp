#pragma once
// The service's JSON protocol (docs/protocol.md): the requests a client may send, parsed and
// checked field by field, and the replies and events the service sends. Parsing never throws and
// never crashes on any input (fuzz/service_protocol_fuzz.cpp); every error names the field.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

namespace uh::service {

using nlohmann::json;

/// The protocol version this build speaks (`hello.protocol`, `welcome.protocol`).
inline constexpr int kProtocolVersion = 1;
/// Larger messages are refused and the connection is closed (WebSocket close code 1009).
inline constexpr std::size_t kMaxMessageBytes = 1 << 20;
/// An announced binary frame (`add_object` with `mesh_binary`) may be this large; only the frame
/// that was announced is read with this limit, every other message with kMaxMessageBytes.
inline constexpr std::size_t kMaxMeshBinaryBytes = std::size_t{64} << 20;
/// Bounds of `subscribe.rate_hz` [Hz] and its default.
inline constexpr double kMinStateRateHz = 1.0;
inline constexpr double kMaxStateRateHz = 1000.0;
inline constexpr double kDefaultStateRateHz = 60.0;

/// A soft object's deformed surface rides along in `state` (`deformed`, docs/protocol.md): at most
/// this often per client [Hz], only when a newer simulation step made it, and no more vertices per
/// message than kMaxDeformedVertices (7 bytes or fewer each, so a state stays well under a
/// megabyte); an object with more is drawn at rest. Coordinates are integers of kDeformedUnitM.
inline constexpr double kDeformedRateHz = 30.0;
inline constexpr std::size_t kMaxDeformedVertices = 32768;
inline constexpr double kDeformedUnitM = 1e-5;

struct Hello {
  int protocol = 0;
  std::string token;  ///< empty when absent
};
struct Open {
  std::optional<std::string> scene;  ///< a scene file; none: the default scene
};
struct Start {
  std::optional<double> seconds;  ///< stop by itself after this long [s]; none: run until stop
};
struct Stop {};
struct Ping {};
struct Close {};
struct Subscribe {
  double rate_hz = kDefaultStateRateHz;
};
struct Unsubscribe {};
struct GetScene {};
struct GetMesh {
  std::string object;  ///< an object's or the tool's name
};
/// The counts of an inline mesh sent in the binary frame that follows its `add_object`: the frame
/// holds `vertices` * 3 little-endian float32 (x, y, z in mesh units), then `triangles` * 3
/// little-endian uint32 vertex indices (counter-clockwise seen from outside).
struct MeshBinary {
  std::int64_t vertices = 0;
  std::int64_t triangles = 0;
  /// The frame's exact size [bytes].
  std::size_t bytes() const { return static_cast<std::size_t>(vertices + triangles) * 12u; }
};
struct AddObject {
  json object;  ///< as an entry of a scene file's `objects` (checked by the scene parser)
  std::optional<MeshBinary> mesh_binary;  ///< the mesh comes in the next binary frame (no `mesh`/`ist`)
};
struct RemoveObject {
  std::string name;
};
struct SetPose {
  std::string object;
  json pose;  ///< {"position": [..], "rotation": [..]} (checked by the scene parser)
};
struct SetWatch {
  std::vector<std::string> objects;
};
struct SetDevice {
  json device;  ///< as a scene file's `tool.device` (checked by the scene parser)
};
struct SetTool {
  json tool;  ///< a JSON merge patch (RFC 7386) of the scene file's `tool` (checked by the scene parser)
};
struct SetRates {
  std::optional<double> haptic_hz;     ///< [Hz]; none: unchanged
  std::optional<double> collision_hz;  ///< [Hz], 0 = free-running; none: unchanged
};

using RequestBody =
    std::variant<Hello, Open, Start, Stop, Ping, Close, Subscribe, Unsubscribe, GetScene, GetMesh, AddObject,
                 RemoveObject, SetPose, SetWatch, SetDevice, SetTool, SetRates>;

/// One parsed message: the request, or what is wrong with it. `id` and `type` are kept whenever
/// they could be read, so that an error reply can echo them.
struct ParsedRequest {
  json id;           ///< the request's `id` (a number or a string), null when absent or unusable
  std::string type;  ///< the request's `type`, empty when unreadable
  std::optional<RequestBody> body;
  std::string error;  ///< set when body is empty
  /// An `add_object` that names `mesh_binary` (valid or not): the next frame, if binary, belongs
  /// to it and is consumed with it (dropped when the request was refused).
  bool announces_binary = false;
};

/// One entry of `state.deformed`: object `object`'s vertices `xyz` (x, y, z per vertex, metres in
/// the object's frame, in the order of its `get_mesh` reply) as made by simulation step `step`.
json deformed_json(std::string_view object, std::uint64_t step, std::span<const float> xyz);

/// Parses one text message. Never throws.
ParsedRequest parse_request(std::string_view text);

/// A reply of `type` that echoes `id` (when not null), with `fields` merged in.
std::string reply(std::string_view type, const json& id, json fields = json::object());

/// `{"type":"error","id":..,"request":..,"message":..}`.
std::string error_reply(const json& id, std::string_view request_type, std::string_view message);

}  // namespace uh::service
