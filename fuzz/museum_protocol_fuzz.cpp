// libFuzzer target for the museum's messages (docs/museum.md): any text read as a server message
// (by the station and the bots) or as a client message (by the server) gives a message or an error
// that says what is wrong, never a crash, an uncaught exception or a hang; a message read is written
// again and read back the same. Seeds: fuzz/museum_seeds/, real messages of every type both ways.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <variant>

#include "uh/museum_protocol/messages.hpp"

namespace {

using namespace uh::museum_protocol;

// writing what was read, then reading and writing that again, gives the same text
void server_round_trip(std::string_view text) {
  const auto read = read_server_message(text);
  if (!read) {
    if (read.error().message.empty()) std::abort();
    return;
  }
  const std::string written = std::visit([](const auto& m) { return write_message(m); }, *read);
  const auto again = read_server_message(written);
  if (!again) std::abort();
  if (std::visit([](const auto& m) { return write_message(m); }, *again) != written) std::abort();
}

std::string write_client(const ClientMessage& body) {
  return std::visit(
      [](const auto& m) -> std::string {
        if constexpr (std::is_same_v<std::decay_t<decltype(m)>, PingMessage>)
          return R"({"type":"ping"})";
        else
          return write_message(m);
      },
      body);
}

void client_round_trip(std::string_view text) {
  const ParsedClientMessage read = read_client_message(text);
  if (read.body.has_value() == !read.error.empty()) std::abort();
  // the error reply echoes the id and the type: it stays JSON
  const std::string reply =
      write_message(ServerError{.id = read.id, .request = read.type, .message = read.error});
  if (!read_server_message(reply)) std::abort();
  if (!read.body) return;
  const std::string written = write_client(*read.body);
  const ParsedClientMessage again = read_client_message(written);
  if (!again.body || write_client(*again.body) != written) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  server_round_trip(text);
  client_round_trip(text);
  return 0;
}
