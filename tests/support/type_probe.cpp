// type_probe: a stand-in for a foreign DDS tool (a spy, a monitor, another
// project's recorder). It links Fast DDS only — no generated code, no
// registerskelgraphTypes() — and learns a topic's type at run time the XTypes
// way: TypeInformation from discovery, the TypeObjects over TypeLookup. It then
// reads samples with a DynamicPubSubType and prints each one as a JSON line
// from a generic DynamicData walker.
//
// Fast DDS 2.9's own DomainParticipant::register_remote_type() crashes on types
// with arrays/sequences of structs (eProsima/Fast-DDS#3296), so the TypeObjects
// are fetched with get_types() by hand; see docs/type-information.md.
//
//   type_probe --profile-file bringup/profiles/loopback.xml --topic T [--count N] [--timeout S]
//   type_probe --profile-file ... --topic T --passive [--timeout S]
//
// --passive registers nothing and only waits for a writer on T to be
// discovered; it exists to show that discovering a full TypeObject still kills
// an unprepared Fast DDS 2.9 process (test type_object_crash_pinned).
// Domain: $SKELGRAPH_DOMAIN (default 0). Exit: 0 done, 1 timeout, 2 usage/setup.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/builtin/data/WriterProxyData.h>
#include <fastdds/rtps/writer/WriterDiscoveryInfo.h>
#include <fastrtps/types/DynamicData.h>
#include <fastrtps/types/DynamicDataFactory.h>
#include <fastrtps/types/DynamicPubSubType.h>
#include <fastrtps/types/DynamicType.h>
#include <fastrtps/types/DynamicTypeMember.h>
#include <fastrtps/types/MemberDescriptor.h>
#include <fastrtps/types/TypeDescriptor.h>
#include <fastrtps/types/TypeObjectFactory.h>
#include <nlohmann/json.hpp>

namespace {

namespace dds = eprosima::fastdds::dds;
// Members keep their declaration order in the output, as in the IDL.
using Json = nlohmann::ordered_json;
namespace rtps = eprosima::fastrtps::rtps;
namespace types = eprosima::fastrtps::types;
using Clock = std::chrono::steady_clock;

struct Options {
  std::string profile_file;
  std::string topic;
  std::size_t count = 1;
  double timeout_s = 15.0;
  bool passive = false;
};

[[noreturn]] void usage(const std::string& why) {
  std::fprintf(stderr,
               "type_probe: %s\nusage: type_probe --profile-file FILE --topic NAME [--count N] [--timeout S] "
               "[--passive]\n",
               why.c_str());
  std::exit(2);
}

Options parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(arg + " needs a value");
      return argv[++i];
    };
    try {
      if (arg == "--profile-file") {
        o.profile_file = value();
      } else if (arg == "--topic") {
        o.topic = value();
      } else if (arg == "--count") {
        o.count = std::stoul(value());
      } else if (arg == "--timeout") {
        o.timeout_s = std::stod(value());
      } else if (arg == "--passive") {
        o.passive = true;
      } else {
        usage("unknown argument " + arg);
      }
    } catch (const std::logic_error&) {
      usage("bad value for " + arg);
    }
  }
  if (o.profile_file.empty() || o.topic.empty()) usage("--profile-file and --topic are required");
  if (o.count == 0) usage("--count must be at least 1");
  return o;
}

int domain_from_env() {
  const char* d = std::getenv("SKELGRAPH_DOMAIN");
  if (d == nullptr || *d == '\0') return 0;
  try {
    return std::stoi(d);
  } catch (const std::logic_error&) {
    usage(std::string("SKELGRAPH_DOMAIN is not a number: ") + d);
  }
}

// ---- what discovery tells us -------------------------------------------------

struct DiscoveredWriter {
  std::string type_name;
  bool reliable = false;
  bool keyed = false;
  bool has_type_object = false;  // the writer sent the full TypeObject (the rejected configuration)
  std::optional<types::TypeInformation> type_information;
};

// The name a complete TypeObject gives its type (empty for kinds we do not name).
std::string object_name(const types::TypeObject& o) {
  const auto& c = o.complete();
  switch (c._d()) {
    case types::TK_STRUCTURE: return c.struct_type().header().detail().type_name();
    case types::TK_ENUM: return c.enumerated_type().header().detail().type_name();
    case types::TK_ALIAS: return c.alias_type().header().detail().type_name();
    case types::TK_UNION: return c.union_type().header().detail().type_name();
    case types::TK_BITMASK: return c.bitmask_type().header().detail().type_name();
    default: return "";
  }
}

// Hashed identifiers (those we must fetch) reachable from `id`; strings,
// primitives and plain collections are described inline and need no fetch.
void hashed_ids(const types::TypeIdentifier& id, std::vector<types::TypeIdentifier>& out) {
  switch (id._d()) {
    case types::EK_COMPLETE: out.push_back(id); break;
    case types::TI_PLAIN_ARRAY_SMALL: hashed_ids(*id.array_sdefn().element_identifier(), out); break;
    case types::TI_PLAIN_ARRAY_LARGE: hashed_ids(*id.array_ldefn().element_identifier(), out); break;
    case types::TI_PLAIN_SEQUENCE_SMALL: hashed_ids(*id.seq_sdefn().element_identifier(), out); break;
    case types::TI_PLAIN_SEQUENCE_LARGE: hashed_ids(*id.seq_ldefn().element_identifier(), out); break;
    case types::TI_PLAIN_MAP_SMALL:
      hashed_ids(*id.map_sdefn().key_identifier(), out);
      hashed_ids(*id.map_sdefn().element_identifier(), out);
      break;
    case types::TI_PLAIN_MAP_LARGE:
      hashed_ids(*id.map_ldefn().key_identifier(), out);
      hashed_ids(*id.map_ldefn().element_identifier(), out);
      break;
    default: break;
  }
}

std::vector<types::TypeIdentifier> dependencies(const types::TypeObject& o) {
  std::vector<types::TypeIdentifier> out;
  const auto& c = o.complete();
  switch (c._d()) {
    case types::TK_STRUCTURE:
      hashed_ids(c.struct_type().header().base_type(), out);
      for (const auto& m : c.struct_type().member_seq()) hashed_ids(m.common().member_type_id(), out);
      break;
    case types::TK_UNION:
      hashed_ids(c.union_type().discriminator().common().type_id(), out);
      for (const auto& m : c.union_type().member_seq()) hashed_ids(m.common().type_id(), out);
      break;
    case types::TK_ALIAS: hashed_ids(c.alias_type().body().common().related_type(), out); break;
    default: break;
  }
  return out;
}

// Collects discovery and TypeLookup results from Fast DDS's listener threads.
class ProbeListener final : public dds::DomainParticipantListener {
 public:
  explicit ProbeListener(std::string topic) : topic_(std::move(topic)) {}

  void on_publisher_discovery(dds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    if (info.status != rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
    if (info.info.topicName().to_string() != topic_) return;
    DiscoveredWriter w;
    w.type_name = info.info.typeName().to_string();
    w.reliable = info.info.m_qos.m_reliability.kind == dds::RELIABLE_RELIABILITY_QOS;
    w.keyed = info.info.topicKind() == rtps::WITH_KEY;
    w.has_type_object = info.info.has_type() && info.info.type().m_type_object._d() != 0;
    if (info.info.has_type_information() && info.info.type_information().assigned()) {
      w.type_information = info.info.type_information().type_information;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (writer_) return;  // the first writer decides the type
      writer_ = std::move(w);
    }
    cv_.notify_all();
  }

  // TypeLookup replies to our get_types() requests.
  void on_type_discovery(dds::DomainParticipant*, const rtps::SampleIdentity&, const eprosima::fastrtps::string_255&,
                         const types::TypeIdentifier* id, const types::TypeObject* object,
                         types::DynamicType_ptr) override {
    if (id == nullptr || object == nullptr || object->_d() != types::EK_COMPLETE) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      received_.emplace_back(*id, *object);
    }
    cv_.notify_all();
  }

  std::optional<DiscoveredWriter> wait_writer(Clock::time_point deadline) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_until(lock, deadline, [&] { return writer_.has_value(); });
    return writer_;
  }

  // Waits (at most until `until`) for TypeObjects and hands over those that arrived.
  std::vector<std::pair<types::TypeIdentifier, types::TypeObject>> wait_objects(Clock::time_point until) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_until(lock, until, [&] { return !received_.empty(); });
    auto out = std::move(received_);
    received_.clear();
    return out;
  }

 private:
  std::string topic_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::optional<DiscoveredWriter> writer_;
  std::vector<std::pair<types::TypeIdentifier, types::TypeObject>> received_;
};

// ---- fetching the type by hand -------------------------------------------------

// Fetches the complete TypeObject of `top` and, recursively, of everything it
// references, registering each with the TypeObjectFactory; returns the built
// DynamicType, or null at the deadline (with what is missing on stderr).
types::DynamicType_ptr fetch_type(dds::DomainParticipant& participant, ProbeListener& listener,
                                  const std::string& type_name, const types::TypeIdentifier& top,
                                  Clock::time_point deadline) {
  auto* factory = types::TypeObjectFactory::get_instance();
  std::vector<types::TypeIdentifier> wanted{top};
  std::vector<types::TypeIdentifier> have;
  auto contains = [](const std::vector<types::TypeIdentifier>& v, const types::TypeIdentifier& id) {
    for (const auto& x : v) {
      if (x == id) return true;
    }
    return false;
  };
  // New identifiers are requested at once; unanswered ones again every
  // second, since a request can go out before the TypeLookup endpoints of the
  // writer's participant are matched, and then nobody answers it.
  std::vector<types::TypeIdentifier> fresh{top};
  auto last_sent = Clock::now();
  while (have.size() < wanted.size()) {
    const auto now = Clock::now();
    if (now >= deadline) {
      std::fprintf(stderr, "type_probe: timeout: TypeLookup answered %zu of %zu TypeObject request(s) for %s\n",
                   have.size(), wanted.size(), type_name.c_str());
      return types::DynamicType_ptr();
    }
    if (!fresh.empty()) {
      participant.get_types(fresh);
      fresh.clear();
      last_sent = now;
    } else if (now - last_sent >= std::chrono::seconds(1)) {
      types::TypeIdentifierSeq missing;
      for (const auto& id : wanted) {
        if (!contains(have, id)) missing.push_back(id);
      }
      participant.get_types(missing);
      last_sent = now;
    }
    for (auto& [id, object] : listener.wait_objects(std::min(deadline, last_sent + std::chrono::seconds(1)))) {
      if (!contains(wanted, id) || contains(have, id)) continue;  // duplicate answer from another server
      const auto name = object_name(object);
      factory->add_type_object(name, &id, &object);
      // Fast DDS 2.9 workaround: naming an array/sequence of this type (done
      // while building the DynamicType) also creates the MINIMAL collection
      // identifier, which dereferences the element's MINIMAL identifier — null
      // for a type known only by its COMPLETE object, so it segfaults. A
      // placeholder MINIMAL identifier under the same name keeps it valid.
      types::TypeIdentifier minimal;
      minimal._d(types::EK_MINIMAL);
      std::memcpy(minimal.equivalence_hash(), id.equivalence_hash(), sizeof(types::EquivalenceHash));
      factory->add_type_identifier(name, &minimal);
      have.push_back(id);
      for (const auto& dep : dependencies(object)) {
        if (!contains(wanted, dep)) {
          wanted.push_back(dep);
          fresh.push_back(dep);
        }
      }
    }
  }
  return factory->build_dynamic_type(type_name, &top, factory->get_type_object(&top));
}

// ---- generic DynamicData → JSON ----------------------------------------------

types::DynamicType_ptr resolve_alias(types::DynamicType_ptr t) {
  while (t && t->get_kind() == types::TK_ALIAS) t = t->get_descriptor()->get_base_type();
  return t;
}

Json walk(types::DynamicData& data, const types::DynamicType_ptr& type);

// The value `id` of `data` (a struct member or a collection element) of type `type`.
Json value_of(types::DynamicData& data, types::MemberId id, const types::DynamicType_ptr& type) {
  const auto t = resolve_alias(type);
  if (!t) return nullptr;
  switch (t->get_kind()) {
    case types::TK_BOOLEAN: return data.get_bool_value(id);
    case types::TK_BYTE: return data.get_byte_value(id);
    case types::TK_INT16: return data.get_int16_value(id);
    case types::TK_INT32: return data.get_int32_value(id);
    case types::TK_INT64: return data.get_int64_value(id);
    case types::TK_UINT16: return data.get_uint16_value(id);
    case types::TK_UINT32: return data.get_uint32_value(id);
    case types::TK_UINT64: return data.get_uint64_value(id);
    case types::TK_FLOAT32: return data.get_float32_value(id);
    case types::TK_FLOAT64: return data.get_float64_value(id);
    case types::TK_FLOAT128: return static_cast<double>(data.get_float128_value(id));
    case types::TK_CHAR8: return std::string(1, data.get_char8_value(id));
    case types::TK_CHAR16: return static_cast<std::uint32_t>(data.get_char16_value(id));
    case types::TK_STRING8: return data.get_string_value(id);
    case types::TK_STRING16: {
      std::string s;  // ASCII is all a probe needs to show; others become '?'
      for (wchar_t c : data.get_wstring_value(id)) s += c < 0x80 ? static_cast<char>(c) : '?';
      return s;
    }
    case types::TK_ENUM: {
      std::string name;
      if (data.get_enum_value(name, id) == ReturnCode_t::RETCODE_OK) return name;
      return data.get_uint32_value(id);
    }
    case types::TK_STRUCTURE:
    case types::TK_ARRAY:
    case types::TK_SEQUENCE: {
      types::DynamicData* inner = data.loan_value(id);
      if (inner == nullptr) return nullptr;
      auto j = walk(*inner, t);
      data.return_loaned_value(inner);
      return j;
    }
    default: {
      char kind[8];
      std::snprintf(kind, sizeof kind, "0x%02x", static_cast<unsigned>(t->get_kind()));
      return Json{{"unsupported_kind", kind}};
    }
  }
}

// Multi-dimensional arrays nest like their IDL declaration; elements are stored flat.
Json walk_array(types::DynamicData& data, const types::DynamicType_ptr& elem, const types::DynamicType_ptr& t,
                          std::vector<std::uint32_t>& position, std::uint32_t dim) {
  auto j = Json::array();
  for (std::uint32_t i = 0; i < t->get_bounds(dim); ++i) {
    position[dim] = i;
    if (dim + 1 < position.size()) {
      j.push_back(walk_array(data, elem, t, position, dim + 1));
    } else {
      j.push_back(value_of(data, data.get_array_index(position), elem));
    }
  }
  return j;
}

Json walk(types::DynamicData& data, const types::DynamicType_ptr& type) {
  const auto t = resolve_alias(type);
  switch (t->get_kind()) {
    case types::TK_STRUCTURE: {
      auto j = Json::object();
      std::map<types::MemberId, types::DynamicTypeMember*> members;  // by id: declaration order
      t->get_all_members(members);
      for (const auto& [id, member] : members) {
        j[member->get_name()] = value_of(data, id, member->get_descriptor()->get_type());
      }
      return j;
    }
    case types::TK_SEQUENCE: {
      auto j = Json::array();
      const auto elem = t->get_descriptor()->get_element_type();
      for (std::uint32_t i = 0; i < data.get_item_count(); ++i) j.push_back(value_of(data, i, elem));
      return j;
    }
    case types::TK_ARRAY: {
      std::vector<std::uint32_t> position(t->get_bounds_size(), 0);
      return walk_array(data, t->get_descriptor()->get_element_type(), t, position, 0);
    }
    default: return nullptr;
  }
}

// ---- main ----------------------------------------------------------------------

struct ParticipantDeleter {
  void operator()(dds::DomainParticipant* p) const {
    p->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(p);
  }
};

int run(const Options& o) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(o.timeout_s));
  auto* factory = dds::DomainParticipantFactory::get_instance();
  // Always the project's profile (loopback in tests), never Fast DDS defaults.
  if (factory->load_XML_profiles_file(o.profile_file) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "type_probe: cannot load profile file %s\n", o.profile_file.c_str());
    return 2;
  }
  dds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile("loopback", qos) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "type_probe: %s has no participant profile 'loopback'\n", o.profile_file.c_str());
    return 2;
  }
  qos.name("type_probe");
  // A tool asks for types; it serves none (it has registered none).
  qos.wire_protocol().builtin.typelookup_config.use_client = !o.passive;
  qos.wire_protocol().builtin.typelookup_config.use_server = false;

  ProbeListener listener(o.topic);
  std::unique_ptr<dds::DomainParticipant, ParticipantDeleter> participant(
      factory->create_participant(domain_from_env(), qos, &listener, dds::StatusMask::none()));
  if (!participant) {
    std::fprintf(stderr, "type_probe: could not create a participant\n");
    return 2;
  }

  const auto writer = listener.wait_writer(deadline);
  if (!writer) {
    std::fprintf(stderr, "type_probe: timeout: no writer on %s discovered within %.1f s\n", o.topic.c_str(),
                 o.timeout_s);
    return 1;
  }
  if (o.passive) {
    // Discovery has already run the code that crashes on a full TypeObject;
    // being here means this Fast DDS survived it.
    std::printf("%s\n", Json{{"topic", o.topic},
                                       {"type", writer->type_name},
                                       {"type_object_announced", writer->has_type_object},
                                       {"type_information_announced", writer->type_information.has_value()},
                                       {"survived", true}}
                            .dump()
                            .c_str());
    return 0;
  }
  if (!writer->type_information) {
    std::fprintf(stderr, "type_probe: the writer of %s (%s) announces no TypeInformation\n", o.topic.c_str(),
                 writer->type_name.c_str());
    return 1;
  }

  const auto& top = writer->type_information->complete().typeid_with_size().type_id();
  auto dyn = fetch_type(*participant, listener, writer->type_name, top, deadline);
  if (!dyn) {
    if (Clock::now() < deadline) std::fprintf(stderr, "type_probe: could not build %s\n", writer->type_name.c_str());
    return 1;
  }

  // Our reader announces no type information, so it matches by type name —
  // the way a tool without the IDL's exact revision has to.
  auto* support = new types::DynamicPubSubType(dyn);
  support->auto_fill_type_information(false);
  support->auto_fill_type_object(false);
  // Keyed or not comes from the type's @key members; DDS matches only
  // readers and writers that agree.
  if (support->m_isGetKeyDefined != writer->keyed) {
    std::fprintf(stderr, "type_probe: warning: %s is %s here but the writer's topic is %s; they will not match\n",
                 writer->type_name.c_str(), support->m_isGetKeyDefined ? "keyed" : "unkeyed",
                 writer->keyed ? "keyed" : "unkeyed");
  }
  dds::TypeSupport type(support);
  if (type.register_type(participant.get(), writer->type_name) != ReturnCode_t::RETCODE_OK) {
    std::fprintf(stderr, "type_probe: could not register %s\n", writer->type_name.c_str());
    return 2;
  }
  auto* topic = participant->create_topic(o.topic, writer->type_name, dds::TOPIC_QOS_DEFAULT);
  auto* subscriber = participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  dds::DataReaderQos rq = dds::DATAREADER_QOS_DEFAULT;
  // A reliable reader would not match a best-effort writer; a best-effort one
  // would drop samples of a reliable writer.
  rq.reliability().kind = writer->reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  rq.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  rq.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  rq.history().depth = 64;
  auto* reader = topic == nullptr || subscriber == nullptr ? nullptr : subscriber->create_datareader(topic, rq);
  if (reader == nullptr) {
    std::fprintf(stderr, "type_probe: could not create a reader on %s\n", o.topic.c_str());
    return 2;
  }

  auto* data_factory = types::DynamicDataFactory::get_instance();
  types::DynamicData* data = data_factory->create_data(dyn);
  std::size_t printed = 0;
  while (printed < o.count) {
    const auto now = Clock::now();
    if (now >= deadline) break;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now).count();
    reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(left / 1000),
                                                                   static_cast<std::uint32_t>(left % 1000) * 1000000));
    dds::SampleInfo info;
    while (printed < o.count && reader->take_next_sample(data, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::printf("%s\n", Json{{"topic", o.topic}, {"type", writer->type_name}, {"data", walk(*data, dyn)}}
                              .dump()
                              .c_str());
      std::fflush(stdout);
      ++printed;
    }
  }
  data_factory->delete_data(data);
  if (printed < o.count) {
    std::fprintf(stderr, "type_probe: timeout: decoded %zu of %zu sample(s) on %s (%s) within %.1f s\n", printed,
                 o.count, o.topic.c_str(), writer->type_name.c_str(), o.timeout_s);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return run(parse_options(argc, argv)); }
