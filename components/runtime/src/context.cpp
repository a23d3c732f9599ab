#include "skelgraph/runtime/context.hpp"

#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <utility>
#include <vector>
#include <stdexcept>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastrtps/config.h>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/attributes/PropertyPolicy.h>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastrtps/utils/IPLocator.h>

#include "skelgraph/runtime/type_policy.hpp"

namespace skelgraph::runtime {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

// The listener of a secure participant: remembers each remote participant
// that brought credentials (an identity token in its announcement) until it
// is authenticated or refused, and passes discovery on to the caller's
// listener. A refusal is printed (a stranger, or a certificate of another CA).
class AuthWatch final : public dds::DomainParticipantListener {
 public:
  AuthWatch(std::string self, dds::DomainParticipantListener* next, std::shared_ptr<const Clock> clock)
      : self_(std::move(self)), next_(next), clock_(std::move(clock)) {}

  void on_participant_discovery(dds::DomainParticipant* p, rtps::ParticipantDiscoveryInfo&& info) override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const auto key = prefix(info.info.m_guid);
      if (info.status == rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
        names_[key] = info.info.m_participantName.to_string();
        if (!info.info.identity_token_.is_nil() && !done_.count(key)) {
          pending_.emplace(key, Pending{names_[key], clock_->monotonic_ns()});
        }
      } else if (info.status != rtps::ParticipantDiscoveryInfo::CHANGED_QOS_PARTICIPANT) {
        const auto it = pending_.find(key);
        if (it != pending_.end() && it->second.seen_stalled) stalled_before_.insert(identity(it->second.name, key));
        if (it != pending_.end()) pending_.erase(it);
        done_.erase(key);
        names_.erase(key);
      }
    }
    if (next_ != nullptr) next_->on_participant_discovery(p, std::move(info));
  }

  void onParticipantAuthentication(dds::DomainParticipant* p, rtps::ParticipantAuthenticationInfo&& info) override {
    std::string name;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const auto key = prefix(info.guid);
      const auto n = names_.find(key);
      name = n != names_.end() ? n->second : std::string("?");
      pending_.erase(key);
      done_.insert(key);
    }
    if (info.status == rtps::ParticipantAuthenticationInfo::UNAUTHORIZED_PARTICIPANT) {
      std::fprintf(stderr, "%s: refused DDS participant '%s' (%s): it did not authenticate (no or other credentials)\n", self_.c_str(),
                   name.c_str(), prefix(info.guid).c_str());
    }
    if (next_ != nullptr) next_->onParticipantAuthentication(p, std::move(info));
  }

  void on_publisher_discovery(dds::DomainParticipant* p, rtps::WriterDiscoveryInfo&& info) override {
    if (next_ != nullptr) next_->on_publisher_discovery(p, std::move(info));
  }
  void on_subscriber_discovery(dds::DomainParticipant* p, rtps::ReaderDiscoveryInfo&& info) override {
    if (next_ != nullptr) next_->on_subscriber_discovery(p, std::move(info));
  }

  std::vector<Context::Unauthenticated> stalled(std::int64_t older_than_ns) {
    std::vector<Context::Unauthenticated> out;
    const auto now = clock_->monotonic_ns();
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [key, p] : pending_) {
      if (now - p.since_ns <= older_than_ns) continue;
      p.seen_stalled = true;
      out.push_back({"'" + p.name + "' (" + key + ")", p.since_ns, stalled_before_.count(identity(p.name, key)) > 0});
    }
    return out;
  }

 private:
  struct Pending {
    std::string name;
    std::int64_t since_ns;
    bool seen_stalled = false;
  };
  // A component of a host, across its restarts: its participant name and the
  // first 6 bytes of its GUID prefix (with DDS Security, derived from the
  // host's certificate).
  static std::string identity(const std::string& name, const std::string& prefix) {
    return name + "@" + prefix.substr(0, 17);
  }
  static std::string prefix(const rtps::GUID_t& g) {
    std::ostringstream os;
    os << g.guidPrefix;
    return os.str();
  }
  std::string self_;
  dds::DomainParticipantListener* next_;
  std::shared_ptr<const Clock> clock_;
  mutable std::mutex mutex_;
  std::map<std::string, Pending> pending_;
  std::set<std::string> done_;
  std::map<std::string, std::string> names_;  // guid prefix -> participant name, of every participant known
  std::set<std::string> stalled_before_;      // identities that stalled with us and then went away
};

namespace {

// Fast DDS keeps loaded profiles in its factory (a process-wide singleton of
// its own); load each file once.
void load_profile_file(const std::string& file) {
  static std::mutex mutex;
  static std::set<std::string> loaded;
  std::lock_guard<std::mutex> lock(mutex);
  if (loaded.count(file) != 0) return;
  if (dds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(file) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("DDS profile file " + file + " could not be loaded (see the Fast DDS error above)");
  }
  loaded.insert(file);
}

// DDS Security from `skelgraph security init` credentials (see DdsConfig::security_dir).
// Returns whether security is on. Paths go to Fast DDS as file:// + absolute path.
bool apply_security(dds::DomainParticipantQos& qos, const DdsConfig& config, const std::string& profile) {
  const std::string* required =
      eprosima::fastrtps::rtps::PropertyPolicyHelper::find_property(qos.properties(), "skelgraph.security");
  const bool must = required != nullptr && *required == "required";
  if (config.security_dir.empty()) {
    if (must) {
      throw std::runtime_error("DDS profile '" + profile +
                               "' needs security credentials: --security DIR or SKELGRAPH_SECURITY_DIR (make them "
                               "with `skelgraph security init DIR --master HOST --sensors HOST,...`)");
    }
    return false;
  }
  namespace fs = std::filesystem;
  const fs::path dir = fs::absolute(config.security_dir);
  const auto need = [&](const fs::path& f) {
    if (!fs::is_regular_file(f)) {
      throw std::runtime_error("security: no " + f.string() + " (credentials for host '" + config.host +
                               "' are made by `skelgraph security init " + dir.string() + " ...` with that host)");
    }
    return "file://" + f.lexically_normal().string();
  };
  const std::vector<std::pair<std::string, std::string>> props = {
      {"dds.sec.auth.plugin", "builtin.PKI-DH"},
      {"dds.sec.auth.builtin.PKI-DH.identity_ca", need(dir / "ca.pem")},
      {"dds.sec.auth.builtin.PKI-DH.identity_certificate", need(dir / "hosts" / (config.host + ".pem"))},
      {"dds.sec.auth.builtin.PKI-DH.private_key", need(dir / "hosts" / (config.host + ".key"))},
      {"dds.sec.access.plugin", "builtin.Access-Permissions"},
      {"dds.sec.access.builtin.Access-Permissions.permissions_ca", need(dir / "ca.pem")},
      {"dds.sec.access.builtin.Access-Permissions.governance", need(dir / "governance.p7s")},
      {"dds.sec.access.builtin.Access-Permissions.permissions", need(dir / "permissions.p7s")},
      {"dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC"},
  };
  for (const auto& [k, v] : props) qos.properties().properties().emplace_back(k, v);
  return true;
}

}  // namespace

Context::Context(std::string name, const DdsConfig& config, dds::DomainParticipantListener* listener)
    : name_(std::move(name)), config_(config), clock_(config.clock ? config.clock : system_clock()), executor_(name_) {
  executor_.on_error([this](const std::string& what) {
    std::fprintf(stderr, "%s: unhandled error in a callback: %s\n", name_.c_str(), what.c_str());
    set_health(HealthState::Error, "unhandled error: " + what);
  });
  register_type_objects();
  const auto file = profile_file(config.profile);
  const auto profile = profile_name(config.profile);
  load_profile_file(file);
  auto* factory = dds::DomainParticipantFactory::get_instance();
  dds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(profile, qos) != ReturnCode_t::RETCODE_OK) {
    throw std::runtime_error("DDS profile file " + file + " has no participant profile named '" + profile + "'");
  }
  qos.name(name_);
  announce_type_information_ = apply_type_policy(qos);
  if (!config.interfaces.empty()) {
    bool any_udp = false;
    for (auto& t : qos.transport().user_transports) {
      if (auto udp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(t)) {
        udp->interfaceWhiteList = config.interfaces;
        any_udp = true;
      }
    }
    if (!any_udp) {
      throw std::runtime_error("DDS profile '" + profile + "' has no UDPv4 transport to restrict to the given interfaces");
    }
  }
  auto& discovery = qos.wire_protocol().builtin.discovery_config;
  for (std::size_t i = 0; i < config.discovery_servers.size(); ++i) {
    const auto address = parse_server_address(config.discovery_servers[i]);
    eprosima::fastrtps::rtps::RemoteServerAttributes server;
    if (!eprosima::fastdds::rtps::get_server_client_default_guidPrefix(static_cast<int>(i), server.guidPrefix)) {
      throw std::runtime_error("at most 256 discovery servers");
    }
    eprosima::fastrtps::rtps::Locator_t locator;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, address.ip);
    locator.port = static_cast<std::uint32_t>(address.port);
    server.metatrafficUnicastLocatorList.push_back(locator);
    discovery.discoveryProtocol = eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT;
    discovery.m_DiscoveryServers.push_back(server);
  }
  if (discovery.discoveryProtocol == eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT &&
      discovery.m_DiscoveryServers.empty()) {
    throw std::runtime_error("DDS profile '" + profile +
                             "' discovers through a discovery server: name it with --discovery-server IP:PORT or "
                             "SKELGRAPH_DISCOVERY_SERVERS (start one with `fastdds discovery -i 0 -l IP -p PORT`)");
  }
  const bool secure = apply_security(qos, config, profile);
  if (secure) auth_watch_ = std::make_unique<AuthWatch>(name_, listener, clock_);
  participant_ = factory->create_participant(static_cast<dds::DomainId_t>(config.domain), qos,
                                             secure ? auth_watch_.get() : listener, dds::StatusMask::none());
  if (participant_ == nullptr) {
    throw std::runtime_error(
        "component '" + name_ + "': could not create a DDS participant on domain " + std::to_string(config.domain) +
        " with profile '" + profile + "' (" + file + ")" +
        (secure ? "; with security on, the usual causes are credentials of another cell, a certificate not signed "
                  "by ca.pem, or governance/permissions not signed by it: check with `skelgraph security check " +
                      config.security_dir + " --host " + config.host + "`"
                : ""));
  }
}

Context::~Context() {
  executor_.stop();
  if (participant_ != nullptr) {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
}


std::vector<Context::Unauthenticated> Context::unauthenticated(std::chrono::milliseconds after) {
  if (!auth_watch_) return {};
  return auth_watch_->stalled(std::chrono::duration_cast<std::chrono::nanoseconds>(after).count());
}


dds::Publisher& Context::publisher() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (publisher_ == nullptr) {
    publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    if (publisher_ == nullptr) throw std::runtime_error("component '" + name_ + "': could not create a DDS publisher");
  }
  return *publisher_;
}

dds::Subscriber& Context::subscriber() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (subscriber_ == nullptr) {
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (subscriber_ == nullptr) throw std::runtime_error("component '" + name_ + "': could not create a DDS subscriber");
  }
  return *subscriber_;
}

dds::Topic& Context::topic(const std::string& name, dds::TopicDataType* support) {
  dds::TypeSupport type(support);  // owns `support` from here on
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = topics_.find(name);
  if (it != topics_.end()) {
    if (it->second->get_type_name() != type.get_type_name()) {
      throw std::runtime_error("component '" + name_ + "': topic " + name + " is already used with type " +
                               it->second->get_type_name() + ", not " + type.get_type_name());
    }
    return *it->second;
  }
  const auto registered = participant_->find_type(type.get_type_name());
  if (registered.empty()) {
    if (!announce_type_information_) withhold_type_information(*support);
    if (participant_->register_type(type) != ReturnCode_t::RETCODE_OK) {
      throw std::runtime_error("component '" + name_ + "': could not register type " + type.get_type_name());
    }
  }
  auto* t = participant_->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  if (t == nullptr) throw std::runtime_error("component '" + name_ + "': could not create topic " + name);
  topics_[name] = t;
  return *t;
}

void EndpointCounter::set_matched(int n) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    matched_ = n < 0 ? 0 : static_cast<std::size_t>(n);
  }
  cv_.notify_all();
}

std::size_t EndpointCounter::matched() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return matched_;
}

bool EndpointCounter::wait_matched(std::size_t n, std::chrono::milliseconds timeout) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return cv_.wait_for(lock, timeout, [&] { return matched_ >= n; });
}

std::shared_ptr<EndpointCounter> Context::add_counter(const std::string& topic, bool is_output) {
  auto c = std::make_shared<EndpointCounter>();
  c->topic = topic;
  c->is_output = is_output;
  std::lock_guard<std::mutex> lock(mutex_);
  counters_.push_back(c);
  return c;
}

void Context::track_reliable_writer(dds::DataWriter* w) {
  std::lock_guard<std::mutex> lock(mutex_);
  reliable_writers_.push_back(w);
}

void Context::untrack_reliable_writer(dds::DataWriter* w) {
  std::lock_guard<std::mutex> lock(mutex_);
  reliable_writers_.erase(std::remove(reliable_writers_.begin(), reliable_writers_.end(), w), reliable_writers_.end());
}

bool Context::flush(std::chrono::milliseconds timeout) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  bool all = true;
  for (auto* w : reliable_writers_) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    const auto ms = std::max<std::int64_t>(0, left.count());
    const eprosima::fastrtps::Duration_t d(static_cast<std::int32_t>(ms / 1000),
                                           static_cast<std::uint32_t>((ms % 1000) * 1000000));
    all = w->wait_for_acknowledgments(d) == ReturnCode_t::RETCODE_OK && all;
  }
  return all;
}

std::vector<std::shared_ptr<EndpointCounter>> Context::counters() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

void Context::set_health(HealthState state, std::string message) {
  std::lock_guard<std::mutex> lock(mutex_);
  health_ = state;
  health_message_ = std::move(message);
}

std::pair<HealthState, std::string> Context::health(std::chrono::nanoseconds failure_window) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto state = health_;
  auto message = health_message_;
  const auto now = clock_->monotonic_ns();
  for (const auto& c : counters_) {
    const auto f = c->failures();
    if (f.count == 0 || now - f.last_mono_ns > failure_window.count()) continue;
    if (state == HealthState::Ok) {
      state = HealthState::Degraded;
      message.clear();
    }
    message += (message.empty() ? "" : "; ") + std::to_string(f.count) + (c->is_output ? " write(s) failed on " : " sample(s) refused on ") +
               c->topic + " (last: " + f.last + ")";
  }
  return {state, message};
}

void EndpointCounter::note_failure(const std::string& what, std::int64_t mono_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++failures_.count;
  failures_.last_mono_ns = mono_ns;
  failures_.last = what;
}

EndpointCounter::Failures EndpointCounter::failures() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failures_;
}

}  // namespace skelgraph::runtime
