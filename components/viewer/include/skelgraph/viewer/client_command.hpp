#pragma once
// Requests a viewer page sends over its WebSocket (JSON text), checked before
// anything acts on them: a malformed one gets an error reply and changes nothing.
//   {"cmd":"play", "kind":"pause"|"resume"|"step"|"speed"|"seek", "value":N, "target":"NAME"}
//       -> a PlayControl for the players of recordings (value: frames for step,
//          speed factor for speed, seconds from the start for seek; target "" or
//          absent: every player)
//   {"cmd":"ping", "id":X}  -> {"type":"pong","id":X} (round trips measured by the page)

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace skelgraph::viewer {

struct ClientCommand {
  enum class Type { Play, Ping } type = Type::Ping;
  std::string play_kind;  // pause, resume, step, speed, seek
  double value = 0.0;
  std::string target;
  nlohmann::json ping_id;
};

struct ParsedCommand {
  bool ok = false;
  std::string error;  // why not, when !ok
  ClientCommand command;
};

// Messages longer than this are refused unread.
inline constexpr std::size_t kMaxClientMessage = 4096;

ParsedCommand parse_client_message(std::string_view text);

}  // namespace skelgraph::viewer
