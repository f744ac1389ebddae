#include "uh/net/ws_url.hpp"

#include <fmt/format.h>

namespace uh::net {
namespace {

bool starts_with(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

// what follows the scheme, or nothing when `url` is not of the form
bool strip_scheme(std::string_view& url, const WsUrlForm& form) {
  const bool ws = starts_with(url, "ws://");
  if (ws) url.remove_prefix(5);
  if (!form.page_address) return ws;
  if (!ws && starts_with(url, "http://")) url.remove_prefix(7);
  return url.find("://") == std::string_view::npos;
}

bool is_port(std::string_view port) {
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string_view::npos)
    return false;
  unsigned value = 0;
  for (const char c : port) value = value * 10 + static_cast<unsigned>(c - '0');
  return value <= 65535;
}

}  // namespace

Result<WsUrl> parse_ws_url(std::string_view url, const WsUrlForm& form) {
  std::string_view rest = url;
  if (!strip_scheme(rest, form)) return Error{std::string(form.wrong_form)};
  const std::size_t slash = rest.find('/');
  const std::string_view authority = rest.substr(0, slash);
  const std::size_t colon = authority.rfind(':');
  WsUrl out;
  out.host = std::string(authority.substr(0, colon));
  out.port = colon == std::string_view::npos ? std::string(form.default_port)
                                             : std::string(authority.substr(colon + 1));
  const bool needs_port = form.default_port.empty();
  if (out.host.empty() || (colon == std::string_view::npos && needs_port) ||
      (colon != std::string_view::npos && out.port.empty()))
    return Error{fmt::format("give the host{}, e.g. {}", needs_port ? " and the port" : "", form.example)};
  if (!is_port(out.port))
    return Error{fmt::format("the port '{}' is not a number from 0 to 65535", out.port)};
  const bool path_given = slash != std::string_view::npos && !form.page_address;
  out.path = path_given ? std::string(rest.substr(slash)) : std::string(form.default_path);
  return out;
}

}  // namespace uh::net
