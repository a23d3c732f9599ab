#include "skelgraph/viewer/viewer_component.hpp"

#include <spdlog/spdlog.h>

#include "skelgraph/msg/json.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"
#include "skelgraph/viewer/access.hpp"
#include "skelgraph/viewer/client_command.hpp"

#ifndef SKELGRAPH_VIEWER_WEB_DIR
#define SKELGRAPH_VIEWER_WEB_DIR ""
#endif

namespace skelgraph::viewer {

runtime::ComponentInfo ViewerComponent::describe() {
  runtime::ComponentInfo info{"viewer", "Live 3-D view of the cell in a web browser (HTTP + WebSocket)", {}};
  info.params.add_string("address", "127.0.0.1",
                         "address to serve the page on (0.0.0.0: every interface; anything but loopback needs credentials)")
      .add_int("port", 8080, "TCP port (0: any free port, printed at start)", 0, 65535)
      .add_double("rate_hz", 30.0, "frames sent to each page per second", 1.0, 120.0)
      .add_int("max_clients", 64, "pages connected at once; more are refused (HTTP 503)", 1, 4096)
      .add_double("max_age_s", 0.5, "a skeleton not updated for this long is no longer drawn", 0.05, 60.0)
      .add_double("fov_h_deg", 57.0, "sensors' horizontal field of view (drawn frustums)", 1.0, 179.0)
      .add_double("fov_v_deg", 43.0, "sensors' vertical field of view", 1.0, 179.0)
      .add_double("far_m", 4.0, "depth of the drawn frustums", 0.1, 50.0)
      .add_string("web_root", "", "folder with the page (default: the one the build made)")
      .add_string("credentials", "",
                  "the cell's credentials directory (skelgraph security init): HTTPS/WSS, and a viewer certificate or "
                  "token for every request (default: the DDS security directory, if any)")
      .add_string("secure", "auto",
                  "auto: HTTPS with credentials on any address but loopback (refused without credentials); "
                  "on: also on loopback",
                  {"auto", "on"});
  return info;
}

namespace {
SceneOptions scene_options(const runtime::Params& p) {
  SceneOptions o;
  o.max_age_ns = static_cast<std::int64_t>(p.get<double>("max_age_s") * 1e9);
  o.fov_h_deg = p.get<double>("fov_h_deg");
  o.fov_v_deg = p.get<double>("fov_v_deg");
  o.far_m = p.get<double>("far_m");
  return o;
}
}  // namespace

ViewerComponent::ViewerComponent(runtime::Context& ctx, const runtime::Params& params)
    : Component(ctx),
      scene_(scene_options(params)),
      address_(params.get<std::string>("address")),
      period_ns_(static_cast<std::int64_t>(1e9 / params.get<double>("rate_hz"))),
      play_pub_(ctx, runtime::topics::kPlayControl),
      raw_sub_(ctx, runtime::topics::kSkeletonRaw, [this](const msg::Skeleton& m, const runtime::SampleMeta&) { on_skeleton(m, now_mono()); },
               [this](const msg::Skeleton& m, const runtime::SampleMeta&) { on_gone(m); }),
      fused_sub_(ctx, runtime::topics::kSkeletonFused, [this](const msg::Skeleton& m, const runtime::SampleMeta&) { on_skeleton(m, now_mono()); },
                 [this](const msg::Skeleton& m, const runtime::SampleMeta&) { on_gone(m); }),
      // The viewer draws the newest truth only. (Reliable, this was the stream
      // missing from the page in 3 clean-clone test runs, stops 20, 24 and 27:
      // nothing received in-process for the whole run while another process
      // read it; the cause in Fast DDS 2.9 was not found.)
      truth_sub_(ctx, runtime::topics::kSkeletonTruth, runtime::newest_only(runtime::topics::kSkeletonTruth.qos),
                 [this](const msg::Skeleton& m, const runtime::SampleMeta&) { on_skeleton(m, now_mono()); },
                 [this](const msg::Skeleton& m, const runtime::SampleMeta&) { on_gone(m); }),
      pose_sub_(ctx, runtime::topics::kCalibration,
                [this](const msg::SensorPose& m, const runtime::SampleMeta&) {
                  if (!scene_.on_pose(skeleton::from_msg(m)))
                    spdlog::warn("{}: pose of {} is in frame '{}', not 'world': not drawn", ctx_.name(),
                                 m.sensor_id().to_string(), m.frame_id().to_string());
                }),
      gesture_sub_(ctx, runtime::topics::kGestureEvent,
                   [this](const msg::GestureEvent& e, const runtime::SampleMeta&) { scene_.on_gesture(e, now_mono()); }),
      status_sub_(ctx, runtime::topics::kStatus,
                  [this](const msg::ComponentStatus& s, const runtime::SampleMeta&) {
                    scene_.on_status(s.component_name().to_string(), s, now_mono());
                  }),
      play_state_sub_(ctx, runtime::topics::kPlayState,
                      [this](const msg::PlayState& s, const runtime::SampleMeta&) { scene_.on_player(s.player().to_string(), s); }),
      robot_sub_(ctx, runtime::topics::kRobotState,
                 [this](const msg::RobotState& s, const runtime::SampleMeta&) { scene_.on_robot(s, now_mono()); }),
      safety_sub_(ctx, runtime::topics::kSafety,
                  [this](const msg::SafetyStatus& s, const runtime::SampleMeta&) { scene_.on_safety(s, now_mono()); }) {
  std::string root = params.get<std::string>("web_root");
  if (root.empty()) root = SKELGRAPH_VIEWER_WEB_DIR;
  Server::Options o;
  o.address = address_;
  o.port = static_cast<std::uint16_t>(params.get<std::int64_t>("port"));
  o.max_clients = static_cast<std::size_t>(params.get<std::int64_t>("max_clients"));
  o.assets = load_assets(root);
  // Anything but loopback: HTTPS/WSS with a certificate or token, or not at all.
  const bool secure = params.get<std::string>("secure") == "on" || !is_loopback_address(address_);
  if (secure) {
    std::string dir = params.get<std::string>("credentials");
    if (dir.empty()) dir = ctx.config().security_dir;
    if (dir.empty())
      throw std::runtime_error(
          "viewer: serving on " + address_ +
          " needs the cell's credentials (anyone who can reach the port would see every worker): make them with "
          "`skelgraph security init DIR ...` and `skelgraph security viewer DIR --server " + ctx.config().host +
          " --address ADDRESS`, then set the viewer's credentials: DIR (or run the secure profile with --security "
          "DIR); or serve on 127.0.0.1");
    const auto c = find_viewer_credentials(dir, ctx.config().host);
    o.tls = Server::Options::Tls{c.cert_file, c.key_file, c.ca_file, c.tokens_file};
  }
  secure_ = o.tls.has_value();
  server_ = std::make_unique<Server>(std::move(o), [this](const std::string& text, bool& bad) {
    return on_client_message(text, bad);
  });
}

ViewerComponent::~ViewerComponent() { on_shutdown(); }

std::string ViewerComponent::url() const {
  return std::string(secure_ ? "https://" : "http://") + address_ + ":" + std::to_string(server_->port()) + "/";
}

void ViewerComponent::on_start() {
  spdlog::info("{}: open {} in a browser", ctx_.name(), url());
  timer_ = ctx_.executor().every(std::chrono::nanoseconds(period_ns_), [this] {
    const auto t = now_mono();
    auto frame = scene_.frame(t);
    frame["viewer"] = ctx_.name();
    frame["made_ns"] = t;  // CLOCK_MONOTONIC of this host: delays measured by clients on it
    server_->broadcast(std::make_shared<const std::string>(frame.dump()));
    const auto made = ++frames_made_;
    // A secure viewer says on its status, once a second, who came in and how many were refused.
    if (secure_ && made % 30 == 1) {
      const auto s = server_->stats();
      ctx_.set_health(runtime::HealthState::Ok,
                      "https: let in " + std::to_string(s.by_certificate) + " by certificate, " +
                          std::to_string(s.by_token) + " by token; refused " + std::to_string(s.tls_refused) +
                          " at TLS, " + std::to_string(s.auth_refused) + " without credentials");
    }
  });
}

void ViewerComponent::on_shutdown() { timer_.cancel(); }

void ViewerComponent::on_skeleton(const msg::Skeleton& m, std::int64_t now_ns) {
  scene_.on_skeleton(skeleton::from_msg(m), now_ns);
}

void ViewerComponent::on_gone(const msg::Skeleton& last) { scene_.on_gone(last.sensor_id().to_string(), last.person_id()); }

// On the server's thread: only the (thread-safe) PlayControl writer is touched here.
std::string ViewerComponent::on_client_message(const std::string& text, bool& bad) {
  const auto parsed = parse_client_message(text);
  if (!parsed.ok) {
    bad = true;
    return nlohmann::json{{"type", "error"}, {"message", parsed.error}}.dump();
  }
  const auto& c = parsed.command;
  if (c.type == ClientCommand::Type::Ping) return nlohmann::json{{"type", "pong"}, {"id", c.ping_id}}.dump();
  msg::PlayControl pc;
  pc.target(c.target);
  pc.kind(c.play_kind == "pause"    ? msg::PLAY_PAUSE
          : c.play_kind == "resume" ? msg::PLAY_RESUME
          : c.play_kind == "step"   ? msg::PLAY_STEP
          : c.play_kind == "seek"   ? msg::PLAY_SEEK
                                    : msg::PLAY_SPEED);
  pc.value(c.value);
  const auto id = ctx_.name() + "-" + std::to_string(++play_requests_);
  pc.request_id(id);
  const bool sent = play_pub_.publish(pc);
  return nlohmann::json{{"type", "play"}, {"request_id", id}, {"sent", sent}}.dump();
}

std::string ViewerComponent::summary() const {
  const auto s = server_->stats();
  return url() + ": " + std::to_string(s.connections) + " page(s) connected (peak " + std::to_string(s.peak_clients) +
         " at once), " + std::to_string(frames_made_.load()) + " frames made, " + std::to_string(s.frames_dropped) +
         " dropped for slow pages, " + std::to_string(s.bad_messages) + " bad client messages, " +
         std::to_string(s.refused) + " refused" +
         (secure_ ? ", " + std::to_string(s.by_certificate) + " requests by certificate and " + std::to_string(s.by_token) +
                        " by token, " + std::to_string(s.tls_refused + s.auth_refused) + " refused access" +
                        (s.last_refusal.empty() ? "" : " (last: " + s.last_refusal + ")")
                  : "");
}

nlohmann::json ViewerComponent::details() const {
  const auto s = server_->stats();
  return {{"url", url()},
          {"port", server_->port()},
          {"frames_made", frames_made_.load()},
          {"clients", s.clients},
          {"peak_clients", s.peak_clients},
          {"connections", s.connections},
          {"refused", s.refused},
          {"messages_sent", s.messages_sent},
          {"frames_dropped", s.frames_dropped},
          {"bad_messages", s.bad_messages},
          {"http_requests", s.http_requests},
          {"secure", secure_},
          {"tls_refused", s.tls_refused},
          {"tls_abandoned", s.tls_abandoned},
          {"auth_refused", s.auth_refused},
          {"by_certificate", s.by_certificate},
          {"by_token", s.by_token},
          {"last_refusal", s.last_refusal},
          {"play_requests", play_requests_.load()}};
}

}  // namespace skelgraph::viewer

SKELGRAPH_REGISTER_COMPONENT(viewer, skelgraph::viewer::ViewerComponent)
