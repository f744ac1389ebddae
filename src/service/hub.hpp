#pragma once
// The service's logic, apart from the network: clients, the one session slot, who controls it,
// subscriptions and events. Everything here runs on the server's network thread (the io_context's
// only thread), so nothing here locks; session builds run on their own threads and post back.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "protocol.hpp"
#include "scene_document.hpp"
#include "uh/controllers/haptic_session.hpp"
#include "uh/net/web_socket_host.hpp"

namespace uh::service {

using net::Endpoint;
using net::Peer;
using net::same_token;

struct HubOptions {
  std::string token;
  std::filesystem::path cache_dir;
  std::filesystem::path working_dir;
  /// What clients may name: the working folder and the cache, or any path (ServerOptions).
  ReadableFolders folders;
  bool raise_priority = false;
};

/// `uh serve`'s endpoint on the WebSocket host (uh/net/web_socket_host.hpp).
class Hub final : public Endpoint {
 public:
  Hub(boost::asio::io_context& io, HubOptions options);
  ~Hub() override;

  ClientId connect(Peer& peer) override;
  void receive(ClientId client, std::string_view text) override;
  void receive_binary(ClientId client, std::span<const std::byte> bytes) override;
  /// The largest message the client may send next: kMaxMessageBytes, or the size of the binary
  /// frame an `add_object` announced (up to kMaxMeshBinaryBytes).
  std::size_t message_limit(ClientId client) const override;
  void disconnect(ClientId client) override;

  /// Shows the program's own session (Server::run_session) to the clients while the program runs
  /// it on its own thread: no client controls it, clients watch its scene, state and events. The
  /// session need not have started yet (its state is zero until then). An error when a client's
  /// session is open or the service is stopping.
  Status show(controllers::HapticSession& session);
  /// The program's session has ended (its owner stopped it): the clients are told, the slot freed.
  void unshow();

  /// Stops the session (zero force) and closes every client. Joins session builds.
  void shutdown() override;

 private:
  // error_reply() with the message's paths as the client may see them (HubOptions::folders)
  std::string refusal(const nlohmann::json& id, std::string_view request_type,
                      std::string_view message) const;
  struct Client {
    Peer* peer = nullptr;
    bool greeted = false;
    int messages_before_hello = 0;
    bool closing = false;  // refused for good (a wrong token): what it sends is ignored
    double rate_hz = 0.0;  // 0: not subscribed
    std::unique_ptr<boost::asio::steady_timer> state_timer;
    // an add_object that announced mesh_binary waits for its frame; without `add` (the request
    // was refused) the frame is dropped when it comes
    struct PendingMesh {
      json req_id;
      std::optional<AddObject> add;
    };
    std::optional<PendingMesh> pending_mesh;
    // the soft objects' surfaces sent in its states: when last, and each object's step
    double deformed_sent_s = 0.0;
    std::vector<std::uint64_t> deformed_steps;
    std::size_t next_deformed = 0;  // the object looked at first next time (a fair turn)
  };
  enum class Phase : std::uint8_t { kOpen, kStarting, kRunning };
  static constexpr ClientId kHost = 0;

  // The open session: its scene (edited by the controller), and the running HapticSession.
  struct Slot {
    ClientId controller = kHost;
    std::optional<SceneDocument> document;     // a client's slot
    std::optional<controllers::Scene> hosted;  // the program's own (show()): its owner stops it
    Phase phase = Phase::kOpen;
    std::unique_ptr<controllers::HapticSession> owned;
    controllers::HapticSession* session = nullptr;
    json start_id;  // the start request, answered when running
    // inline meshes written for this slot: removed (with their packing cache) when it closes
    std::vector<std::filesystem::path> inline_meshes;
    // `mesh` replies already made, by object name: a get_mesh flood costs no reading or encoding
    std::map<std::string, std::string, std::less<>> mesh_replies;
    const controllers::Scene& scene() const { return document ? document->scene() : *hosted; }
  };

  void handle(ClientId id, Client& c, const json& req_id, const std::string& type, const RequestBody& body);
  // each returns an error text, or empty when it replied itself
  std::string on_hello(ClientId id, Client& c, const json& req_id, const Hello& h);
  std::string on_open(ClientId id, const json& req_id, const Open& o);
  std::string on_start(ClientId id, const json& req_id, const Start& s);
  std::string on_stop(ClientId id, const json& req_id);
  std::string on_close(ClientId id, const json& req_id);
  std::string on_subscribe(ClientId id, Client& c, const json& req_id, const Subscribe& s);
  std::string on_edit(ClientId id, const json& req_id, const std::string& type, const RequestBody& body);
  // set_pose while the session runs: the document and the running session's object
  std::string move_object(ClientId id, const json& req_id, const SetPose& p);
  // an add_object with mesh_binary: held until its frame comes (error text, or empty)
  std::string on_announce_mesh(ClientId id, Client& c, const ParsedRequest& req);
  std::string on_mesh_frame(ClientId id, const Client::PendingMesh& pending,
                            std::span<const std::byte> bytes);
  // the inline mesh checked and written off this thread: added to the document if it still may be
  void mesh_written(std::uint64_t generation, ClientId id, const Client::PendingMesh& pending,
                    Result<InlineMesh> written);
  std::string on_get_mesh(ClientId id, Client& c, const json& req_id, const GetMesh& g);

  // an error text when `id` may not change the session
  std::string check_control(ClientId id, bool needs_open) const;
  void build_finished(std::uint64_t generation, Result<std::unique_ptr<controllers::HapticSession>> built,
                      std::optional<double> seconds);
  // stops a running session; the report's JSON (or null when nothing ran); `state_out` gets the
  // state after the stop (with the zero force sent)
  json stop_session(Status* status_out = nullptr, json* state_out = nullptr);
  // stops the running session and sends its controller an unsolicited `stopped` with `reason`
  void stop_by_itself(const std::string& reason);
  void close_slot();
  void broadcast_session(std::string_view status);
  void send_state(ClientId id);
  // the soft objects' surfaces a newer step made since `c`'s last, within the protocol's bounds
  void add_deformed(Client& c, json& state);
  void poll_events();
  void send_to(ClientId id, std::string text);

  boost::asio::io_context& io_;
  HubOptions options_;
  std::map<ClientId, Client> clients_;
  ClientId next_id_ = 1;
  std::optional<Slot> slot_;
  std::uint64_t generation_ = 0;  // bumped whenever the slot changes; stale builds are dropped
  boost::asio::steady_timer stop_timer_;
  boost::asio::steady_timer event_timer_;
  std::jthread builder_;  // the one session build at a time
  std::jthread mesher_;   // the one inline mesh checked and written at a time
  bool meshing_ = false;  // mesher_ works (network thread)
  bool shut_down_ = false;
  std::vector<float> deformed_scratch_;  // a soft object's vertices on their way into a state
};

}  // namespace uh::service
