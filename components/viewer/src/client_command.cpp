#include "skelgraph/viewer/client_command.hpp"

#include <cmath>

namespace skelgraph::viewer {

ParsedCommand parse_client_message(std::string_view text) {
  ParsedCommand out;
  const auto refuse = [&](std::string why) {
    out.ok = false;
    out.error = std::move(why);
    return out;
  };
  if (text.size() > kMaxClientMessage)
    return refuse("message of " + std::to_string(text.size()) + " bytes; at most " +
                  std::to_string(kMaxClientMessage) + " accepted");
  const auto j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return refuse("not JSON");
  if (!j.is_object()) return refuse("expected a JSON object with \"cmd\"");
  const auto cmd = j.find("cmd");
  if (cmd == j.end() || !cmd->is_string()) return refuse("expected \"cmd\": \"play\" or \"ping\"");
  ClientCommand c;
  if (*cmd == "ping") {
    c.type = ClientCommand::Type::Ping;
    c.ping_id = j.value("id", nlohmann::json());
  } else if (*cmd == "play") {
    c.type = ClientCommand::Type::Play;
    const auto kind = j.find("kind");
    if (kind == j.end() || !kind->is_string()) return refuse("play: expected \"kind\": pause, resume, step, speed or seek");
    c.play_kind = kind->get<std::string>();
    if (c.play_kind != "pause" && c.play_kind != "resume" && c.play_kind != "step" && c.play_kind != "speed" &&
        c.play_kind != "seek")
      return refuse("play: unknown kind '" + c.play_kind.substr(0, 32) + "' (pause, resume, step, speed, seek)");
    if (const auto v = j.find("value"); v != j.end()) {
      if (!v->is_number()) return refuse("play: \"value\" must be a number");
      c.value = v->get<double>();
      if (!std::isfinite(c.value)) return refuse("play: \"value\" must be finite");
    } else if (c.play_kind == "step") {
      c.value = 1.0;
    } else if (c.play_kind == "speed") {
      return refuse("play speed: expected \"value\" (1 real time, 2 twice as fast)");
    } else if (c.play_kind == "seek") {
      return refuse("play seek: expected \"value\" (seconds from the start of the recording)");
    }
    if (const auto t = j.find("target"); t != j.end()) {
      if (!t->is_string()) return refuse("play: \"target\" must be a player's name");
      c.target = t->get<std::string>();
      if (c.target.size() > 63) return refuse("play: \"target\" longer than 63 characters");
    }
  } else {
    return refuse("unknown cmd '" + (cmd->get<std::string>().substr(0, 64)) + "' (play, ping)");
  }
  out.ok = true;
  out.command = std::move(c);
  return out;
}

}  // namespace skelgraph::viewer
