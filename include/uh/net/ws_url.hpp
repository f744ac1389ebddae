#pragma once
/// \file
/// The one reader of a WebSocket server's address (`ws://HOST[:PORT][/PATH]`): the Haply driver's
/// service URL and the museum client's server address are both read here, each in its own form.

#include <string>
#include <string_view>

#include "uh/core/result.hpp"

namespace uh::net {

/// Where a WebSocket server listens.
struct WsUrl {
  std::string host;        ///< a name or an address, as given
  std::string port;        ///< decimal, 0..65535
  std::string path = "/";  ///< the handshake's target, from '/'
};

/// How a URL may be written where it is read (aggregate; the defaults are plain `ws://` URLs).
struct WsUrlForm {
  /// The error for a URL that is not of this form, e.g. "expected ws://HOST:PORT[/PATH]".
  std::string_view wrong_form = "expected ws://HOST:PORT[/PATH]";
  /// Shown in the error for a missing host (or port), e.g. "ws://127.0.0.1:10001".
  std::string_view example = "ws://127.0.0.1:80";
  /// The port when the URL gives none; empty: the URL must give one.
  std::string_view default_port = "80";
  /// The path when the URL gives none.
  std::string_view default_path = "/";
  /// Also `http://HOST:PORT/...` and `HOST:PORT`: the address of a server's page, whose socket is
  /// at `default_path` whatever path the URL names (`uh museum serve` prints its page's address).
  bool page_address = false;
};

/// HOST, PORT and PATH of `url` in `form`; an error says what is missing or wrong (the caller
/// names the URL and where it came from).
Result<WsUrl> parse_ws_url(std::string_view url, const WsUrlForm& form = {});

}  // namespace uh::net
