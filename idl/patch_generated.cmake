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

# Key hashes: the generated getKey() serializes the key into a buffer kept
# from call to call and hashes it with the alignment padding between fields
# left as whatever the previous key put there (fastcdr skips padding without
# writing it). So one participant writing two keyed topics of one type
# (the simulator: ground truth "truth" and raw "sensor1" skeletons) gave one
# person several instance handles, and a writer never freed them. The patch
# zeroes the buffer first, as the key hash's definition (zero padding) wants.
set(file ${GEN_DIR}/skelgraphPubSubTypes.cxx)
file(READ ${file} text)
# (Patterns without ';': CMake would read the matches as lists.)
set(buffer "eprosima::fastcdr::FastBuffer fastbuffer\\(reinterpret_cast<char\\*>\\(m_keyBuffer\\),([ \n]*)([A-Za-z0-9_]+)::getKeyMaxCdrSerializedSize\\(\\)\\)")
string(REGEX MATCHALL "${buffer}" keys "${text}")
list(LENGTH keys key_count)
string(REGEX MATCHALL "m_keyBuffer\\)," all_keys "${text}")
list(LENGTH all_keys all_count)
if(key_count EQUAL 0 OR NOT key_count EQUAL all_count)
  message(FATAL_ERROR "patch_generated.cmake: ${key_count} of ${all_count} getKey() buffers have the expected shape in ${file}; fastddsgen changed, revisit idl/patch_generated.cmake")
endif()
string(REGEX REPLACE "${buffer}"
  "std::memset(m_keyBuffer, 0, \\2::getKeyMaxCdrSerializedSize());\n            eprosima::fastcdr::FastBuffer fastbuffer(reinterpret_cast<char*>(m_keyBuffer),\\1\\2::getKeyMaxCdrSerializedSize())"
  text "${text}")
string(REGEX MATCHALL "std::memset\\(m_keyBuffer, 0," zeroed "${text}")
list(LENGTH zeroed zeroed_count)
if(NOT zeroed_count EQUAL key_count)
  message(FATAL_ERROR "patch_generated.cmake: zeroed ${zeroed_count} of ${key_count} key buffers in ${file}; revisit idl/patch_generated.cmake")
endif()
file(WRITE ${file} "#include <cstring>\n${text}")
