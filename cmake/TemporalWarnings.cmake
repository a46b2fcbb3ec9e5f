# Settings every target of the project links to, instead of directory-wide flags.
add_library(temporal_warnings INTERFACE)
add_library(temporal::warnings ALIAS temporal_warnings)
target_compile_options(temporal_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow=local -Wno-unused-parameter
  # GCC 12 reports `"text" + std::string(...)` as a memcpy overlap at -O2 (GCC bug 105651, a false positive in
  # libstdc++'s inlined string code); the warning says nothing about this project's code.
  $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-restrict>)

# Release code is built for the machine it runs on (the suite is a measurement tool: speed is part of
# what it reports), with vectorisation enabled and without -ffast-math so NaN checks keep working.
add_library(temporal_optimize INTERFACE)
add_library(temporal::optimize ALIAS temporal_optimize)
option(TEMPORAL_NATIVE "Compile for the host CPU (-march=native)" ON)
if(TEMPORAL_NATIVE)
  target_compile_options(temporal_optimize INTERFACE $<$<NOT:$<CONFIG:Debug>>:-march=native>)
endif()
target_compile_options(temporal_optimize INTERFACE $<$<NOT:$<CONFIG:Debug>>:-O3 -fno-math-errno>)

if(TEMPORAL_SANITIZE)
  target_compile_options(temporal_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer)
  target_link_options(temporal_warnings INTERFACE -fsanitize=address,undefined)
endif()
