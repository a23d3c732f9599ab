#pragma once

namespace skelgraph::msg {

// The text of idl/skelgraph.idl, embedded at build time. Recordings store it as
// the schema of every skelgraph type so other tools can decode the data.
const char* idl_text();

}  // namespace skelgraph::msg
