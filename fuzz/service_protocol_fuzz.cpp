// libFuzzer target for the service's message parser (uh serve, docs/protocol.md): any text must
// give a request or an error that says what is wrong, never a crash, an uncaught exception or a
// hang; the error reply made of it (which echoes the request's id and type) must be valid JSON.
// Seeds: fuzz/protocol_seeds/, one message of every type (scripts/test.sh passes it read-only).

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace uh::service;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ParsedRequest request = parse_request(text);
  if (request.body.has_value() == !request.error.empty()) std::abort();
  if (!request.id.is_null() && !request.id.is_number_integer() && !request.id.is_string()) std::abort();
  if (request.body)
    if (const auto* s = std::get_if<Subscribe>(&*request.body))
      if (!(s->rate_hz >= kMinStateRateHz && s->rate_hz <= kMaxStateRateHz)) std::abort();
  const std::string reply = request.body ? uh::service::reply("ok", request.id)
                                         : error_reply(request.id, request.type, request.error);
  const auto again = json::parse(reply, nullptr, false);
  if (again.is_discarded() || !again.is_object()) std::abort();
  return 0;
}
