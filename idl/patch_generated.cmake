# Run after fastddsgen (cmake -P): with -typeobject, fastddsgen 2.x makes every
# constructor of every generated struct call registerskelgraphTypes(), which
# re-registers all type objects each time: building one msg::Skeleton (16
# constructors) cost ~1.6 ms of CPU, and a 30 Hz simulator a whole core at 20x.
# The patch makes the registration run once per process (std::call_once).
# The build stops if the generated code no longer has the expected shape.
set(file ${GEN_DIR}/skelgraphTypeObject.cxx)
file(READ ${file} text)
set(head "void registerskelgraphTypes()\n{")
string(FIND "${text}" "${head}" at)
if(at EQUAL -1)
  message(FATAL_ERROR "patch_generated.cmake: '${head}' not found in ${file}; fastddsgen changed, revisit idl/patch_generated.cmake")
endif()
string(REPLACE "${head}"
"#include <mutex>\nstatic void registerskelgraphTypes_once();\nvoid registerskelgraphTypes()\n{\n    static std::once_flag once;\n    std::call_once(once, registerskelgraphTypes_once);\n}\nstatic void registerskelgraphTypes_once()\n{"
  text "${text}")
file(WRITE ${file} "${text}")
