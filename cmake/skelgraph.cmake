# Helper functions that keep the per-folder CMake files small.

set(SKELGRAPH_WARNINGS -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
# In a unity build a source file is #included into its batch, and GCC then takes
# a class with a member of an anonymous-namespace type (the Impl of a pimpl) for
# one declared in a header: -Wsubobject-linkage would warn on correct code.
if(CMAKE_UNITY_BUILD AND CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  list(APPEND SKELGRAPH_WARNINGS -Wno-subobject-linkage)
endif()

# skelgraph_library(NAME SOURCES ... [DEPS ...] [PUBLIC_INCLUDE dir])
# A static library with the project's warnings and its include/ folder public.
function(skelgraph_library name)
  cmake_parse_arguments(A "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${A_SOURCES})
  target_include_directories(${name} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_compile_options(${name} PRIVATE ${SKELGRAPH_WARNINGS})
  target_link_libraries(${name} PUBLIC ${A_DEPS})
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# skelgraph_component(KIND kind CORE core_target ADAPTER_SOURCES ... [DEPS ...])
# The adapter library of a component; KIND is the name launch files use. The
# adapter's .cpp ends with SKELGRAPH_REGISTER_COMPONENT(kind, Class); the
# program's registry is generated from the list collected here.
function(skelgraph_component)
  cmake_parse_arguments(A "" "KIND;TARGET" "SOURCES;DEPS" ${ARGN})
  skelgraph_library(${A_TARGET} SOURCES ${A_SOURCES} DEPS skelgraph_runtime ${A_DEPS})
  set_property(GLOBAL APPEND PROPERTY SKELGRAPH_COMPONENT_KINDS ${A_KIND})
  set_property(GLOBAL APPEND PROPERTY SKELGRAPH_COMPONENT_TARGETS ${A_TARGET})
endfunction()

# skelgraph_test(NAME SOURCES ... [DEPS ...] [DDS] [LABELS ...])
# A GoogleTest executable registered with ctest. DDS tests run in a private
# network namespace with only `lo` (tests/netns-lo.sh), on their own domain id.
set_property(GLOBAL PROPERTY SKELGRAPH_NEXT_TEST_DOMAIN 10)
function(skelgraph_test name)
  cmake_parse_arguments(A "DDS" "" "SOURCES;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${A_SOURCES})
  target_compile_options(${name} PRIVATE ${SKELGRAPH_WARNINGS})
  target_link_libraries(${name} PRIVATE ${A_DEPS} GTest::gtest GTest::gtest_main)
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${PROJECT_BINARY_DIR}/tests)
  if(A_DDS)
    skelgraph_next_domain(domain)
    add_test(NAME ${name} COMMAND ${PROJECT_SOURCE_DIR}/tests/netns-lo.sh $<TARGET_FILE:${name}>)
    set_tests_properties(${name} PROPERTIES
      ENVIRONMENT "SKELGRAPH_DOMAIN=${domain};SKELGRAPH_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
      LABELS "${A_LABELS}" TIMEOUT 300)
  else()
    add_test(NAME ${name} COMMAND ${name})
    set_tests_properties(${name} PROPERTIES
      ENVIRONMENT "SKELGRAPH_SOURCE_DIR=${PROJECT_SOURCE_DIR}" LABELS "${A_LABELS}" TIMEOUT 300)
  endif()
endfunction()

# skelgraph_script_test(NAME SCRIPT [ARGS ...]) — a shell test in its own loopback
# namespace. The script gets the skelgraph program, then ARGS (helper programs
# as $<TARGET_FILE:...>, a mode word).
function(skelgraph_script_test name script)
  cmake_parse_arguments(A "" "" "ARGS" ${ARGN})
  skelgraph_next_domain(domain)
  add_test(NAME ${name}
    COMMAND ${PROJECT_SOURCE_DIR}/tests/netns-lo.sh bash ${script} $<TARGET_FILE:skelgraph> ${A_ARGS})
  set_tests_properties(${name} PROPERTIES
    ENVIRONMENT "SKELGRAPH_DOMAIN=${domain};SKELGRAPH_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    LABELS "integration" TIMEOUT 300)
endfunction()

# Hands out a distinct DDS domain id per test so tests can run in parallel.
function(skelgraph_next_domain out)
  get_property(d GLOBAL PROPERTY SKELGRAPH_NEXT_TEST_DOMAIN)
  math(EXPR next "${d} + 1")
  set_property(GLOBAL PROPERTY SKELGRAPH_NEXT_TEST_DOMAIN ${next})
  set(${out} ${d} PARENT_SCOPE)
endfunction()

# skelgraph_npm_ci(DIR PACKAGE_DIR STAMP_PACKAGE COMMENT OUT_STAMP): npm packages
# a build step needs, installed by `npm ci` from PACKAGE_DIR's package.json and
# package-lock.json into DIR (once; again when the lock file changes).
# OUT_STAMP: the installed STAMP_PACKAGE's package.json, to depend on.
function(skelgraph_npm_ci dir package_dir stamp_package comment out_stamp)
  find_program(NPM npm)
  if(NOT NPM)
    message(FATAL_ERROR "npm not found: ${comment} (Debian: apt install npm; tools/run installs it)")
  endif()
  set(stamp ${dir}/node_modules/${stamp_package}/package.json)
  add_custom_command(OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND ${CMAKE_COMMAND} -E copy ${package_dir}/package.json ${package_dir}/package-lock.json ${dir}
    COMMAND ${NPM} ci --prefix ${dir} --no-audit --no-fund --loglevel=error
    COMMAND ${CMAKE_COMMAND} -E touch ${stamp}
    DEPENDS ${package_dir}/package.json ${package_dir}/package-lock.json
    COMMENT "${comment}")
  set(${out_stamp} ${stamp} PARENT_SCOPE)
endfunction()

# skelgraph_check_core(TARGETS ... FORBIDDEN regex)
# Fails the configure step when a core library (pure C++: Eigen, std and a
# few file-format libraries) reaches, directly or through its dependencies,
# a library matching the regex (the generated DDS types, Fast DDS, OpenCV).
function(_skelgraph_reaches target forbidden chain out)
  if(NOT TARGET ${target})
    if("${target}" MATCHES "${forbidden}")
      set(${out} "${chain}" PARENT_SCOPE)
    endif()
    return()
  endif()
  get_target_property(_imported ${target} IMPORTED)
  if(_imported)
    get_target_property(_deps ${target} INTERFACE_LINK_LIBRARIES)
  else()
    get_target_property(_deps ${target} LINK_LIBRARIES)
  endif()
  if("${target}" MATCHES "${forbidden}")
    set(${out} "${chain}" PARENT_SCOPE)
    return()
  endif()
  if(NOT _deps)
    return()
  endif()
  foreach(dep IN LISTS _deps)
    string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" dep "${dep}")
    _skelgraph_reaches(${dep} "${forbidden}" "${chain} -> ${dep}" found)
    if(found)
      set(${out} "${found}" PARENT_SCOPE)
      return()
    endif()
  endforeach()
endfunction()

function(skelgraph_check_core)
  cmake_parse_arguments(A "" "FORBIDDEN" "TARGETS" ${ARGN})
  foreach(t IN LISTS A_TARGETS)
    if(NOT TARGET ${t})
      message(FATAL_ERROR "skelgraph_check_core: no target ${t}")
    endif()
    _skelgraph_reaches(${t} "${A_FORBIDDEN}" "${t}" found)
    if(found)
      message(FATAL_ERROR "core library ${t} must not link DDS or OpenCV, but does: ${found}")
    endif()
  endforeach()
endfunction()
