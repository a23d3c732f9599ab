#pragma once
// Wire types change only by appending fields, and every reader here still
// decodes what older schemas wrote: recordings outlive the tools that made
// them. Schema history of the types that changed:
//   Skeleton 1 -> 2: capture_oldest_ns, capture_newest_ns and the per-joint
//   covariance appended. A schema-1 skeleton reads as capture stamps equal to
//   stamp_ns and no covariance (all zero).
// from_cdr<Skeleton> (cdr.hpp) accepts both; a tool that passes payloads on
// unchanged (a player, a merge) calls upgrade_cdr first, so what it sends or
// writes is always the current schema.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "skelgraph/msg/messages.hpp"

namespace skelgraph::msg {

// The current schema of a Skeleton (2).
inline constexpr int kSkeletonSchema = 2;

// A schema-1 Skeleton payload (CDR with its encapsulation header) as the
// current type; empty when the bytes are not exactly one.
std::optional<Skeleton> skeleton_from_schema1(const void* data, std::size_t size);

// Whether payloads of `type_name` stored under this schema text (an MCAP
// channel's schema: our whole IDL, or empty) can be of an older schema, so a
// pass-through reader must run upgrade_cdr on them.
bool may_be_older_schema(const std::string& type_name, const std::string& schema_text);

// The payload re-encoded in the current schema when it is an older schema of
// `type_name`; empty when it already is current (or not a type of ours).
std::optional<std::vector<std::uint8_t>> upgrade_cdr(const std::string& type_name, const void* data, std::size_t size);

}  // namespace skelgraph::msg
